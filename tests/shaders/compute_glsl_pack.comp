#version 450
// GLSL.std.450 pack/unpack, frexp and ldexp (float, double and half), one set of edge values per invocation.
#extension GL_EXT_shader_explicit_arithmetic_types : require
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) readonly buffer Floats { vec4 f[]; };
layout(set = 0, binding = 1, std430) readonly buffer Words { uvec2 w[]; };
layout(set = 0, binding = 2, std430) readonly buffer Exps { ivec4 e[]; };
layout(set = 0, binding = 3, std430) readonly buffer Doubles { double d[]; };
layout(set = 0, binding = 4, std430) writeonly buffer OutU { uint ou[]; };
layout(set = 0, binding = 5, std430) writeonly buffer OutF { float of[]; };
layout(set = 0, binding = 6, std430) writeonly buffer OutI { int oi[]; };
layout(set = 0, binding = 7, std430) writeonly buffer OutD { double od[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 x = f[i];
  uint p = w[i].x;
  ivec4 n = e[i];
  double dv = d[i];

  uint u = i * 8u;
  ou[u + 0] = packSnorm4x8(x);
  ou[u + 1] = packUnorm4x8(x);
  ou[u + 2] = packSnorm2x16(x.xy);
  ou[u + 3] = packUnorm2x16(x.zw);
  ou[u + 4] = packHalf2x16(x.xy);
  ou[u + 5] = packHalf2x16(x.zw);
  uvec2 dw = unpackDouble2x32(dv);
  ou[u + 6] = dw.x;
  ou[u + 7] = dw.y;

  uint o = i * 26u;
  vec4 a = unpackSnorm4x8(p);
  vec4 b = unpackUnorm4x8(p);
  vec2 c = unpackSnorm2x16(p), g = unpackUnorm2x16(p), h = unpackHalf2x16(p);
  for (int k = 0; k < 4; ++k) {
    of[o + k] = a[k];
    of[o + 4 + k] = b[k];
  }
  of[o + 8] = c.x; of[o + 9] = c.y;
  of[o + 10] = g.x; of[o + 11] = g.y;
  of[o + 12] = h.x; of[o + 13] = h.y;
  ivec4 fe;
  vec4 fs = frexp(x, fe);
  vec4 ld = ldexp(x, n);
  float16_t hx = uint16BitsToHalf(uint16_t(p & 0xffffu));
  int he;
  float16_t hs = frexp(hx, he);
  for (int k = 0; k < 4; ++k) {
    of[o + 14 + k] = fs[k];
    of[o + 18 + k] = ld[k];
  }
  of[o + 22] = float(hs);
  of[o + 23] = float(ldexp(hx, n.x));
  of[o + 24] = float(ldexp(hx, n.y));
  of[o + 25] = 0.0;

  uint q = i * 6u;
  for (int k = 0; k < 4; ++k) oi[q + k] = fe[k];
  oi[q + 4] = he;
  int de;
  double ds = frexp(dv, de);
  oi[q + 5] = de;

  uint r = i * 4u;
  od[r + 0] = packDouble2x32(w[i]);
  od[r + 1] = ds;
  od[r + 2] = ldexp(dv, n.z);
  od[r + 3] = ldexp(dv, n.w);
}
