#!/usr/bin/env python3
"""Runs examples/pathtracer on the Cornell box at a tiny resolution and checks what it rendered and reported.

Usage: check_pathtracer.py <pathtracer> <work dir>

- the image is not black, and the pixels known (from the camera and the room's geometry, see below) to see the red
  wall, the green wall and the ceiling light are red-dominant, green-dominant and saturated white;
- it reports its ray count: at least one ray per path (the camera ray), at most the camera ray plus two per bounce
  (the next path ray and a shadow ray), and Mrays/s;
- a glTF file's alphaMode MASK material with a texture is cut where the texture's alpha is below its cutoff;
- the image depends on the seed only: rendering in passes of 1 sample gives the same image (to one 8-bit step: the
  sums are added in another order), another seed a different one.
The validation layer is not used: Debian's (1.3.239) predates VK_EXT_pipeline_library_group_handles, drops its
feature structure from vkCreateDevice's chain, and does not count library groups in a linked pipeline.
"""
import os
import re
import struct
import subprocess
import sys
import zlib

W, H, SPP, BOUNCES = 32, 24, 8, 4


def read_png(path):
    """Decodes an 8-bit RGBA non-interlaced PNG (what stb_image_write writes) into rows of (r, g, b, a)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and colour == 6 and interlace == 0, f"unexpected PNG format {header}"
    raw, bpp, stride = zlib.decompress(idat), 4, width * 4
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * 4:x * 4 + 4]) for x in range(width)])
        prev = line
    return width, height, rows


def run(exe, out, *extra):
    args = [exe, "--scene", "cornell", "--width", str(W), "--height", str(H), "--spp", str(SPP), "--bounces",
            str(BOUNCES), "--out", out, *extra]
    p = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print(p.stdout, end="")
    if p.returncode != 0:
        sys.exit(f"FAIL: {' '.join(args)} exited with {p.returncode}")
    if re.search(r"^vkrt: ", p.stdout, re.M):
        sys.exit("FAIL: vkrt reported something")
    return p.stdout


def png_bytes(width, height, rgba):
    """A PNG (filter 0 on every row) of rows of RGBA tuples."""
    raw = b"".join(b"\0" + bytes(c for p in row for c in p) for row in rgba)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write_gltf(path, right_texel_alpha):
    """Two upright quads facing +z: a red opaque one (x -2..-0.2) and a green alphaMode MASK one (x 0.2..2) whose
    base colour texture is 2x1 texels, white, alpha 255 on the left (u < 0.5) and right_texel_alpha on the right."""
    def quad(x0, x1):
        pos = struct.pack("<12f", x0, 0, 0, x1, 0, 0, x1, 1, 0, x0, 1, 0)
        uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
        return pos, uv

    blob, views, accessors = b"", [], []
    for x0, x1 in ((-2.0, -0.2), (0.2, 2.0)):
        pos, uv = quad(x0, x1)
        for data, kind, ctype, count, extra in ((pos, "VEC3", 5126, 4, {"min": [x0, 0, 0], "max": [x1, 1, 0]}),
                                                (uv, "VEC2", 5126, 4, {}),
                                                (struct.pack("<6H", 0, 1, 2, 0, 2, 3), "SCALAR", 5123, 6, {})):
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
            accessors.append(dict({"bufferView": len(views) - 1, "componentType": ctype, "count": count,
                                   "type": kind}, **extra))
            blob += data + b"\0" * (-len(data) % 4)
    image = png_bytes(2, 1, [[(255, 255, 255, 255), (255, 255, 255, right_texel_alpha)]])
    import base64
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0},
                                   {"attributes": {"POSITION": 3, "TEXCOORD_0": 4}, "indices": 5, "material": 1}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.05, 0.05, 1], "metallicFactor": 0}},
                      {"pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.8, 0.05, 1], "metallicFactor": 0,
                                                "baseColorTexture": {"index": 0}},
                       "alphaMode": "MASK", "alphaCutoff": 0.5}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}],
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": views,
        "accessors": accessors,
    }
    import json
    with open(path, "w") as f:
        json.dump(doc, f)


def check_gltf_mask(exe, work, check):
    """A glTF file's MASK material cuts its quad where the texture's alpha is below alphaCutoff (the any-hit
    shader): the green quad shows about half as many pixels as the same quad with an opaque texture."""
    counts = []
    for alpha in (0, 255):
        gltf, png = os.path.join(work, f"mask{alpha}.gltf"), os.path.join(work, f"mask{alpha}.png")
        write_gltf(gltf, alpha)
        p = subprocess.run([exe, "--scene", gltf, "--width", "48", "--height", "32", "--spp", "4", "--bounces", "2",
                            "--out", png], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        print(p.stdout, end="")
        check(p.returncode == 0, f"the glTF scene with texture alpha {alpha} renders")
        if p.returncode != 0:
            return
        _, _, px = read_png(png)
        red = sum(1 for row in px for q in row if q[0] > 1.5 * q[1] and q[0] > 1.5 * q[2])
        green = sum(1 for row in px for q in row if q[1] > 1.5 * q[0] and q[1] > 1.5 * q[2])
        counts.append((red, green))
    (red_cut, green_cut), (red_full, green_full) = counts
    check(red_cut > 20 and red_full > 20, f"the opaque red quad is seen ({red_cut} and {red_full} pixels)")
    check(green_full > 20 and 0.3 * green_full < green_cut < 0.75 * green_full,
          f"the MASK quad loses its transparent half ({green_cut} green pixels, {green_full} with an opaque texture)")


def main():
    exe, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failures = []

    def check(ok, what):
        print(("ok: " if ok else "FAIL: ") + what)
        if not ok:
            failures.append(what)

    first = os.path.join(work, "cornell.png")
    log = run(exe, first, "--seed", "7")
    m = re.search(r"pathtracer: (\d+) rays \(([\d.]+) per path\) in ([\d.]+) s: ([\d.]+) Mrays/s", log)
    check(m is not None, "the run reports its rays and Mrays/s")
    if m:
        rays, paths = int(m.group(1)), W * H * SPP
        check(paths <= rays <= paths * (1 + 2 * BOUNCES), f"{rays} rays for {paths} paths of up to {BOUNCES} bounces")
        check(rays > 2 * paths, f"{rays} rays: paths bounce and cast shadow rays (more than 2 rays a path)")
        check(float(m.group(4)) > 0, "Mrays/s is positive")
    check(re.search(r"group handles queried on the 3 libraries equal the linked pipeline's", log) is not None,
          "the SBT's handles come from the libraries and equal the linked pipeline's")
    check(re.search(r"pathtracer: 8/8 spp \(100%\)", log) is not None, "progress reaches 8/8 spp")

    width, height, px = read_png(first)
    check((width, height) == (W, H), f"the image is {W}x{H}")
    mean = sum(sum(p[:3]) for row in px for p in row) / (3 * W * H)
    check(mean > 20, f"the image is not black (mean {mean:.1f})")
    # The camera (0, 1, 3.9) looks down -z with a 40-degree vertical field of view; the room spans x -1..1, y 0..2,
    # z -1..1. At mid height the left wall (x = -1) covers image columns 5..9 and the right wall 22..26; the light
    # (y = 1.98, x and z in -0.25..0.25) covers columns 14..17 of row 3.
    def average(x0, x1, y0, y1):
        ps = [px[y][x] for y in range(y0, y1 + 1) for x in range(x0, x1 + 1)]
        return tuple(sum(p[k] for p in ps) / len(ps) for k in range(3))

    red = average(6, 8, 10, 13)
    check(red[0] > 60 and red[0] > 2 * red[1] and red[0] > 2 * red[2], f"the left wall is red {red}")
    green = average(23, 25, 10, 13)
    check(green[1] > 40 and green[1] > 1.5 * green[0] and green[1] > 1.5 * green[2], f"the right wall is green {green}")
    light = average(15, 16, 3, 3)
    # Its emission, (17, 12, 4), saturates red and green; blue is below 255 where the light's edge cuts the pixel.
    check(light[0] > 250 and light[1] > 250 and light[2] > 150, f"the light is bright {light}")

    # The same seed in passes of one sample: the same image; another seed: another image.
    passes = os.path.join(work, "cornell_passes.png")
    log = run(exe, passes, "--seed", "7", "--pass-spp", "1")
    check("pathtracer: 1/8 spp" in log, "passes of 1 sample report their progress")
    _, _, px2 = read_png(passes)
    diff = max(abs(a - b) for r1, r2 in zip(px, px2) for p1, p2 in zip(r1, r2) for a, b in zip(p1, p2))
    check(diff <= 1, f"rendering in 8 passes gives the same image (largest difference {diff})")
    other = os.path.join(work, "cornell_seed8.png")
    run(exe, other, "--seed", "8")
    _, _, px3 = read_png(other)
    differing = sum(p1 != p3 for r1, r3 in zip(px, px3) for p1, p3 in zip(r1, r3))
    check(differing > W * H // 4, f"another seed gives another image ({differing} pixels differ)")

    check_gltf_mask(exe, work, check)

    if failures:
        sys.exit(f"FAIL: {len(failures)} checks failed")
    print("PASS")


if __name__ == "__main__":
    main()
