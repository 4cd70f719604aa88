#version 460
// SPMD against scalar (tests/spirv/spmd_test.cpp): divergent if/else and returns, loops with per-lane trip
// counts, break and continue, a Mandelbrot loop, short-circuit operators (phis), a per-lane local array indexed
// per lane, vectors indexed dynamically, a uniform matrix times varying vectors, per-lane out-of-bounds loads and stores, consecutive and scattered accesses, vector arithmetic and
// GLSL.std.450 functions (component-wise and on whole vectors). Any workgroup shape (specialization constants 0, 1,
// 2).
layout(local_size_x_id = 0, local_size_y_id = 1, local_size_z_id = 2) in;
layout(set = 0, binding = 0, std430) buffer Out { uint o[]; };
layout(set = 0, binding = 1, std430) readonly buffer In { float v[]; };
layout(set = 0, binding = 2, std430) buffer Out2 { uint o2[]; };
layout(push_constant) uniform P { uint n; uint maxIter; uint bias; float scale; } pc;

void main() {
  uvec3 size = gl_WorkGroupSize * gl_NumWorkGroups;
  uint id = gl_GlobalInvocationID.x + size.x * (gl_GlobalInvocationID.y + size.y * gl_GlobalInvocationID.z);
  if (id >= pc.n) return;
  float x = v[id];
  uint r;
  if ((id & 1u) == 0u) {
    r = uint(x * 3.0 * pc.scale);
  } else {
    r = floatBitsToUint(sqrt(abs(x)) + float(gl_LocalInvocationIndex));
  }
  uint acc = 0u;
  for (uint k = 0u; k < (id % 13u) + 1u; ++k) {
    if (k == 5u) continue;
    if (acc > 40u + id % 7u) break;
    acc += k * (id % 5u + 1u);
  }
  float cx = -2.0 + 3.0 * fract(x * 7.31), cy = -1.5 + 3.0 * fract(x * 3.17);
  float zx = 0.0, zy = 0.0;
  uint it = 0u;
  while (it < pc.maxIter && zx * zx + zy * zy <= 4.0) {
    float t = zx * zx - zy * zy + cx;
    zy = 2.0 * zx * zy + cy;
    zx = t;
    ++it;
  }
  uint arr[8];
  for (int j = 0; j < 8; ++j) arr[j] = id * uint(j) + gl_LocalInvocationID.y;
  uint pick = arr[id % 8u];
  arr[(id + 3u) % 8u] = 77u;
  pick += arr[(id + 3u) % 8u] + arr[id % 11u];  // index 8..10: out of bounds, reads zero
  bool both = (id % 3u == 0u) || (x > 0.5 && id % 2u == 1u);
  float g = v[id * 7u + pc.bias];  // past the buffer's end for some lanes: zero
  vec3 p = vec3(x, g, float(acc));
  vec3 q = p * 2.0 + p.zxy - vec3(gl_LocalInvocationID);
  float d = dot(p, q) + clamp(x, 0.25, 0.75) + mix(x, g, 0.3) + floor(x * 10.0) + max(q.x, q.z);
  vec3 c = cross(p, q) + normalize(q + 0.5) + reflect(p, normalize(q + 1.0)) + faceforward(p, q, p.yzx);
  d += length(p) + distance(p, q) + c.x * 0.5 + c.y * 0.25 + c.z;
  d += (p + q)[id % 3u] + vec3(x, 1.5, 2.5)[pc.bias % 3u];  // a vector indexed per lane and uniformly
  // A uniform matrix times a varying vector, both ways.
  mat3 m = mat3(vec3(pc.scale, 0.25, -1.0), vec3(0.5, pc.scale * 2.0, 0.125), vec3(float(pc.bias), 1.0, 0.75));
  vec3 mq = m * q, qm = q * m;
  d += mq.x + mq.y * 0.5 + mq.z + qm.x * 0.25 + qm.y + qm.z * 0.125;
  uint base = id * 8u;
  o[base + 0u] = r;
  o[base + 1u] = acc;
  o[base + 2u] = it;
  o[base + 3u] = pick;
  o[base + 4u] = both ? 1u : 0u;
  o[base + 5u] = floatBitsToUint(g);
  o[base + 6u] = floatBitsToUint(d);
  o[base + 7u + ((id % 4u) == 3u ? 1000000u : 0u)] = id + gl_WorkGroupID.z;  // some lanes out of bounds: dropped
  o2[id] = acc + it * 3u;
  if (id == 0u) o2[pc.n] = pc.maxIter;  // a uniform address under a mask
}
