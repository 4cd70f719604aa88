#version 450
// Convergence on the SPMD path (spmd_test.cpp, Spmd.ConvergentLoopsAndInlinedReturns): a 64 x 8 grid of rays against
// a buffer of spheres, as the public compute ray tracing samples write it. The loops over the spheres keep their
// counter uniform around divergent selections that end inside them (the spheres load whole, as uniform structs, into
// the inlined functions' parameters); `hit` returns early, `firstBlocker` returns from inside its loop (the pipeline
// merges its returns to inline it) and continues from it on a varying condition; the ray direction is normalized from
// a varying x and a y uniform in a row of 16 lanes; `side` returns constants; the row's extent comes from a storage
// image's size query.
layout(local_size_x = 16, local_size_y = 4) in;
struct Sphere {
  vec4 sphere;  // centre, radius
  vec3 color;
  float shine;
  int id;
  int kind;
};
layout(std430, binding = 0) readonly buffer Spheres { Sphere spheres[]; };
layout(std430, binding = 1) buffer Out { vec4 o[]; };  // 4 per invocation
layout(set = 0, binding = 2, r32f) uniform readonly image2D extent;  // 64 x 8: the grid

float hit(vec3 ro, vec3 rd, Sphere s) {
  vec3 oc = ro - s.sphere.xyz;
  float b = dot(oc, rd);
  float h = b * b - (dot(oc, oc) - s.sphere.w * s.sphere.w);
  if (h < 0.0) return -1.0;
  return -b - sqrt(h);
}

// Constants returned under a varying condition: the lanes meet at the inlined returns' merge with values that vary.
int side(float v) {
  if (v < 0.0) return 1;
  return 2;
}

int firstBlocker(vec3 ro, vec3 rd, int skip) {
  for (int i = 0; i < spheres.length(); i++) {
    if (spheres[i].id == skip) continue;
    if (hit(ro, rd, spheres[i]) > 0.001) return spheres[i].id;
  }
  return -1;
}

void main() {
  const ivec2 size = imageSize(extent);
  const uvec2 g = gl_GlobalInvocationID.xy;
  const uint idx = g.y * uint(size.x) + g.x;
  const vec3 ro = vec3(0.0, 0.0, -6.0);
  const vec3 rd = normalize(vec3((float(g.x) - 32.0) / 96.0, (float(g.y) - 4.0) / 24.0, 1.0));
  float nearest = 1e30;
  int id = -1;
  uint kinds = 0u;
  vec3 color = vec3(0.0);
  for (int i = 0; i < spheres.length(); i++) {
    Sphere s = spheres[i];
    const float t = hit(ro, rd, s);
    if (t > 0.0 && t < nearest) {
      nearest = t;
      id = s.id;
      color = s.color * s.shine;
    }
    kinds += uint(s.kind);
  }
  const int blocker = id >= 0 ? firstBlocker(ro + rd * nearest, normalize(vec3(1.0, 0.1, 0.3)), id) : -2;
  o[idx * 4u + 0u] = vec4(rd, nearest);
  o[idx * 4u + 1u] = vec4(color, float(kinds));
  o[idx * 4u + 2u] = vec4(float(id), float(blocker), float(size.x), float(size.y));
  o[idx * 4u + 3u] = vec4(float(side(float(int(g.x % 3u) - 1))), float(side(rd.y)), 0.0, 0.0);
}
