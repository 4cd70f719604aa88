// Inputs and expected outputs of tests/shaders/compute_small_types.comp (8/16-bit integers and 16-bit
// floats), computed on the CPU in the same widths; shared by the unit and the end-to-end test.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>

namespace vkrt::testing {

// Inputs and expected outputs of compute_small_types.comp, computed here in the same widths.
struct SmallIn {
  int8_t a8[64];
  uint8_t b8[64];
  int16_t a16[64];
  uint16_t b16[64];
  _Float16 h[64];
};
struct SmallOut {
  int8_t sum8[64];
  uint8_t mul8[64];
  int16_t div16[64];
  uint16_t shr16[64];
  _Float16 hmath[64];
  int8_t v8[64][4];
  _Float16 hv[64][2];
  int32_t widened[64];
  _Float16 hconv[64];
  _Float16 hmathFused[64];  // expected only: hmath with p * q + p fused
};

inline SmallIn smallInput() {
  SmallIn in{};
  for (int i = 0; i < 64; ++i) {
    in.a8[i] = int8_t(i * 37 - 100);
    in.b8[i] = uint8_t(i * 91 + 7);
    in.a16[i] = int16_t(i * 1237 - 30000);
    in.b16[i] = uint16_t(i * 4099 + 3);
    in.h[i] = _Float16(float(i - 30) * 0.3125f);
  }
  in.a16[10] = 0;  // a division by zero guarded in the shader
  return in;
}

inline SmallOut smallExpected(const SmallIn& in) {
  SmallOut o{};
  for (int i = 0; i < 64; ++i) {
    int8_t x = in.a8[i], y = in.a8[63 - i];
    o.sum8[i] = int8_t(x + y);
    o.mul8[i] = uint8_t(in.b8[i] * in.b8[(i + 5) & 63] + 3);
    int16_t d = in.a16[(i + 1) & 63];
    o.div16[i] = d == 0 ? int16_t(0) : int16_t(in.a16[i] / d);
    o.shr16[i] = uint16_t((in.b16[i] >> 3) ^ uint16_t(in.b16[i] << 5));
    _Float16 p = in.h[i], q = in.h[(i + 7) & 63];
    o.hmath[i] = _Float16(_Float16(_Float16(p * q) + p) - q);
    o.hmathFused[i] = _Float16(_Float16(float(p) * float(q) + float(p)) - q);  // p * q is exact in float
    o.v8[i][0] = x;
    o.v8[i][1] = y;
    o.v8[i][2] = int8_t(x - y);
    o.v8[i][3] = int8_t(-x);
    o.hv[i][0] = _Float16(p * _Float16(0.5f));
    o.hv[i][1] = _Float16(q * _Float16(0.5f));
    o.widened[i] = int32_t(x) * 1000 + int32_t(in.a16[i]) + int32_t(in.b8[i]);
    o.hconv[i] = _Float16(float(in.a16[i]) * 0.125f);
  }
  return o;
}

inline void expectSmall(const SmallOut& got, const SmallOut& want) {
  for (int i = 0; i < 64; ++i) {
    EXPECT_EQ(got.sum8[i], want.sum8[i]) << i;
    EXPECT_EQ(got.mul8[i], want.mul8[i]) << i;
    EXPECT_EQ(got.div16[i], want.div16[i]) << i;
    EXPECT_EQ(got.shr16[i], want.shr16[i]) << i;
    // Half arithmetic: each operation rounded to half, or p * q + p fused (SPIR-V allows the contraction).
    EXPECT_TRUE(got.hmath[i] == want.hmath[i] || got.hmath[i] == want.hmathFused[i])
        << i << ": " << float(got.hmath[i]) << " vs " << float(want.hmath[i]) << " or " << float(want.hmathFused[i]);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(got.v8[i][k], want.v8[i][k]) << i;
    for (int k = 0; k < 2; ++k) EXPECT_EQ(float(got.hv[i][k]), float(want.hv[i][k])) << i;
    EXPECT_EQ(got.widened[i], want.widened[i]) << i;
    EXPECT_EQ(float(got.hconv[i]), float(want.hconv[i])) << i;
  }
}

}  // namespace vkrt::testing
