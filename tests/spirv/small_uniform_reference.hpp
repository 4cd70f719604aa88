// Inputs and expected outputs of tests/shaders/compute_small_uniform_push.comp (8/16-bit members of a std140
// uniform block and of a push-constant block), shared by the unit and the end-to-end test. The blocks are
// built byte by byte at the offsets std140 and the push-constant layout give, padding filled with 0xab so
// that a wrong offset reads garbage; the expected values come from the C++ values, not from those bytes.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace vkrt::testing {

struct SmallUniformValues {
  int8_t s8 = -100;
  uint8_t u8 = 200;
  int16_t s16 = -30000;
  uint16_t u16 = 60000;
  _Float16 h = _Float16(-2.5f);
  int8_t v8[4] = {-1, 127, -128, 5};
  _Float16 hv[4] = {_Float16(0.5f), _Float16(-65504.0f), _Float16(0.0009765625f), _Float16(5.9604644775390625e-8f)};
  uint16_t uv[2] = {65535, 1};
  _Float16 h3[3] = {_Float16(1.0f), _Float16(-0.0f), _Float16(3.140625f)};
  int8_t tail = -7;
  int16_t arr[4] = {-1, 32767, -32768, 1234};
  uint8_t pair[2][2] = {{1, 2}, {250, 251}};
  // push constants
  uint8_t pu8 = 255;
  int8_t ps8 = -1;
  int16_t ps16 = -2;
  _Float16 ph = _Float16(7.75f);
  uint16_t pu16 = 40000;
  int8_t pv8[2] = {-50, 60};
  _Float16 phv[2] = {_Float16(-0.125f), _Float16(1000.0f)};
  int8_t pa8[3] = {-3, 4, -128};
  _Float16 pha[2] = {_Float16(0.333f), _Float16(-1e-5f)};
};

constexpr uint32_t kSmallUniformInts = 24, kSmallUniformFloats = 12, kSmallUniformInvocations = 8;

template <class T>
void putAt(std::vector<uint8_t>& bytes, size_t offset, const T& v) {
  std::memcpy(bytes.data() + offset, &v, sizeof v);
}

inline std::vector<uint8_t> smallUniformBlock(const SmallUniformValues& v) {
  std::vector<uint8_t> b(144, 0xab);
  putAt(b, 0, v.s8);
  putAt(b, 1, v.u8);
  putAt(b, 2, v.s16);
  putAt(b, 4, v.u16);
  putAt(b, 6, v.h);
  putAt(b, 8, v.v8);
  putAt(b, 16, v.hv);
  putAt(b, 24, v.uv);
  putAt(b, 32, v.h3);
  putAt(b, 38, v.tail);
  for (int k = 0; k < 4; ++k) putAt(b, 48 + 16 * k, v.arr[k]);
  for (int k = 0; k < 2; ++k) putAt(b, 112 + 16 * k, v.pair[k]);
  return b;
}

inline std::vector<uint8_t> smallPushBlock(const SmallUniformValues& v) {
  std::vector<uint8_t> b(24, 0xab);
  putAt(b, 0, v.pu8);
  putAt(b, 1, v.ps8);
  putAt(b, 2, v.ps16);
  putAt(b, 4, v.ph);
  putAt(b, 6, v.pu16);
  putAt(b, 8, v.pv8);
  putAt(b, 12, v.phv);
  putAt(b, 16, v.pa8);
  putAt(b, 20, v.pha);
  return b;
}

inline void expectSmallUniform(const int32_t* o, const float* f, const SmallUniformValues& v) {
  for (uint32_t i = 0; i < kSmallUniformInvocations; ++i) {
    SCOPED_TRACE("invocation " + std::to_string(i));
    const int32_t* r = o + i * kSmallUniformInts;
    int32_t want[20] = {v.s8,    v.u8,    v.s16,   v.u16,    v.v8[0],      v.v8[1],          v.v8[2],
                        v.v8[3], v.uv[0], v.uv[1], v.tail,   v.arr[i % 4], v.pair[i % 2][1], v.pu8,
                        v.ps8,   v.ps16,  v.pu16,  v.pv8[0], v.pv8[1],     v.pa8[i % 3]};
    for (int k = 0; k < 20; ++k) EXPECT_EQ(r[k], want[k]) << "integer output " << k;
    const float* g = f + i * kSmallUniformFloats;
    float wantF[12] = {float(v.h),     float(v.hv[0]),  float(v.hv[1]),  float(v.hv[2]),
                       float(v.hv[3]), float(v.h3[0]),  float(v.h3[1]),  float(v.h3[2]),
                       float(v.ph),    float(v.phv[0]), float(v.phv[1]), float(v.pha[i % 2])};
    for (int k = 0; k < 12; ++k)
      EXPECT_EQ(std::memcmp(&g[k], &wantF[k], 4), 0)
          << "float output " << k << ": got " << g[k] << " want " << wantF[k];
  }
}

}  // namespace vkrt::testing
