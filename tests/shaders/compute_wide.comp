#version 460
#extension GL_ARB_gpu_shader_int64 : require
// 64-bit integers and doubles: arithmetic, shifts, comparisons and conversions.
layout(local_size_x = 4) in;
struct Pair { int64_t a; uint64_t b; };
layout(set = 0, binding = 0, std430) readonly buffer In { Pair p[]; } inp;
layout(set = 0, binding = 1, std430) readonly buffer InD { double d[]; } inD;
layout(set = 0, binding = 2, std430) writeonly buffer Out { uint64_t r[]; } outp;
layout(set = 0, binding = 3, std430) writeonly buffer OutD { double r[]; } outD;

void main() {
  uint i = gl_GlobalInvocationID.x;
  int64_t x = inp.p[i].a;
  uint64_t y = inp.p[i].b;
  double d = inD.d[i];
  uint o = i * 8u;
  outp.r[o + 0] = uint64_t(x) * y + 0x100000000ul;
  outp.r[o + 1] = uint64_t(x >> 7);
  outp.r[o + 2] = y >> 33;
  outp.r[o + 3] = y / 3ul;
  outp.r[o + 4] = uint64_t(x / 5l);
  outp.r[o + 5] = (x < int64_t(y) ? 1ul : 0ul) | (uint64_t(x) < y ? 2ul : 0ul);
  outp.r[o + 6] = uint64_t(int64_t(d * 1000.0));
  outp.r[o + 7] = uint64_t(uint(y) + uint(x));
  outD.r[i * 3u + 0u] = d * d + double(x) * 0.5LF;
  outD.r[i * 3u + 1u] = sqrt(abs(d)) + floor(d);
  outD.r[i * 3u + 2u] = double(float(d));
}
