#version 450
// Storage image loads and stores on the SPMD path (tests/spirv/spmd_image_test.cpp): a 64 x 8 grid of invocations over
// 40 x 5 images, so that coordinates leave the images on every side (a row of 16 lanes: partly left of the image,
// inside, partly right of it, wholly right of it). Each invocation reads and writes only texels no
// other invocation touches (p: its own, consecutive along x; q: a permutation of the grid, scattered), so the bytes do
// not depend on the order the invocations run in.
layout(local_size_x = 16, local_size_y = 2) in;
layout(set = 0, binding = 0, rgba8) readonly uniform image2D src8;  // read at p and q
layout(set = 0, binding = 1, rgba8) uniform image2D dst8;           // read and written at p
layout(set = 0, binding = 2, r32ui) uniform uimage2D ids;           // read and written at q
layout(set = 0, binding = 3, rgba32f) uniform image2D wide;         // read and written at q
layout(set = 0, binding = 4, rg32i) uniform iimage2D pairs;         // read and written at p
layout(set = 0, binding = 5, r32f) uniform image2DArray layers;     // layer 1, at p (the lanes' calls)
layout(set = 0, binding = 6) buffer Out { uvec4 o[]; };             // 7 per invocation
layout(push_constant) uniform Values { vec4 value[8]; };            // dst8's texels (edge cases)

void main() {
  const ivec2 g = ivec2(gl_GlobalInvocationID.xy);
  const uint i = uint(g.y * 64 + g.x);
  const ivec2 p = g - ivec2(2, 1);
  const ivec2 q = ivec2((g.x * 7) % 64 - 4, g.y - 1);
  o[i * 7 + 0] = floatBitsToUint(imageLoad(src8, p));
  o[i * 7 + 1] = floatBitsToUint(imageLoad(src8, q));
  o[i * 7 + 2] = floatBitsToUint(imageLoad(dst8, p));
  o[i * 7 + 3] = imageLoad(ids, q);
  o[i * 7 + 4] = floatBitsToUint(imageLoad(wide, q));
  o[i * 7 + 5] = uvec4(imageLoad(pairs, p));
  o[i * 7 + 6] = floatBitsToUint(imageLoad(layers, ivec3(p, 1)));
  // Divergent stores: each image written by some lanes of a batch only.
  if (g.x % 3 != 1) imageStore(dst8, p, value[i % 8u]);
  if (g.x % 2 == 0) imageStore(ids, q, uvec4(1000u + i));
  else imageStore(wide, q, vec4(float(i), -float(i), float(i) * 0.5, 1.0 / float(i + 1u)));
  if (g.y != 3) imageStore(pairs, p, ivec4(int(i), -int(i), 7, 9));
  imageStore(layers, ivec3(p, 1), vec4(float(i) * 0.25));
}
