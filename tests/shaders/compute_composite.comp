#version 460
// Vectors, matrices (std140 uniform block with column- and row-major matrices), struct arrays, swizzles and
// dynamic indexing.
layout(local_size_x = 4) in;
struct Item {
  vec3 pos;
  float w;
  ivec2 id;
};
layout(set = 0, binding = 0, std140) uniform Params {
  mat4 m;
  layout(row_major) mat3 r;
  vec4 v[4];
  Item items[2];
} p;
layout(set = 0, binding = 1, std430) buffer Out { vec4 r[]; } outp;

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 a = p.v[i];
  vec4 r0 = p.m * a;
  vec3 r1 = p.r * a.xyz;
  vec3 r2 = a.zyx * p.r;
  mat2 t = mat2(a.x, a.y, a.z, a.w);
  mat2 tt = transpose(t) * t;
  Item it = p.items[i % 2u];
  float local[4] = float[4](1.0, 2.0, 3.0, 4.0);
  local[i] += it.w;
  outp.r[i * 5u + 0u] = r0;
  outp.r[i * 5u + 1u] = vec4(r1, p.m[i][i]);
  outp.r[i * 5u + 2u] = vec4(r2, dot(a, a.wzyx));
  outp.r[i * 5u + 3u] = vec4(tt[0], tt[1]);
  outp.r[i * 5u + 4u] = vec4(it.pos * float(it.id.x + it.id.y), local[i] + local[(i + 1u) % 4u]);
}
