#version 450
// 8/16-bit integers and 16-bit floats: storage (std430 arrays of int8_t, uint8_t, int16_t, uint16_t,
// float16_t and their vectors) and arithmetic in those widths (wrapping, signed division, shifts,
// conversions between widths, half-precision float math).
#extension GL_EXT_shader_explicit_arithmetic_types : require
layout(local_size_x = 32) in;
layout(set = 0, binding = 0) readonly buffer In {
  int8_t a8[64];
  uint8_t b8[64];
  int16_t a16[64];
  uint16_t b16[64];
  float16_t h[64];
};
layout(set = 0, binding = 1) buffer Out {
  int8_t sum8[64];
  uint8_t mul8[64];
  int16_t div16[64];
  uint16_t shr16[64];
  float16_t hmath[64];
  i8vec4 v8[64];
  f16vec2 hv[64];
  int32_t widened[64];
  float16_t hconv[64];
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  int8_t x = a8[i], y = a8[63 - i];
  sum8[i] = x + y;
  mul8[i] = b8[i] * b8[(i + 5) & 63u] + uint8_t(3);
  int16_t d = a16[(i + 1) & 63u];
  div16[i] = d == int16_t(0) ? int16_t(0) : a16[i] / d;
  shr16[i] = (b16[i] >> 3) ^ uint16_t(b16[i] << 5);
  float16_t p = h[i], q = h[(i + 7) & 63u];
  hmath[i] = p * q + p - q;
  v8[i] = i8vec4(x, y, x - y, int8_t(-x));
  hv[i] = f16vec2(p, q) * float16_t(0.5);
  widened[i] = int32_t(x) * 1000 + int32_t(a16[i]) + int32_t(b8[i]);
  hconv[i] = float16_t(float(a16[i]) * 0.125);
}
