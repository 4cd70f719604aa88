// Inputs and the expected output bytes of tests/shaders/compute_scalar_layout.comp (GL_EXT_scalar_block_layout),
// shared by the unit and the end-to-end test. Blocks are built at the offsets the scalar rules give (written
// out here by hand, not computed); the values are small multiples of 1/4, so every sum and product is exact.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

namespace vkrt::testing {

constexpr uint32_t kScalarInvocations = 8;
constexpr size_t kScalarInBytes = 172 + 20 * kScalarInvocations, kScalarUniformBytes = 48,
                 kScalarOutBytes = 100 + 20 * kScalarInvocations;

struct ScalarLayoutValues {
  float a[3] = {1.25f, -2.5f, 0.75f}, b = 3.5f, arr[8][3], c = -1.75f, v2[2] = {0.5f, 6.25f};
  struct Item {
    float p[3], w;
  } items[3] = {{{1, 2, 3}, 0.25f}, {{-1, -2, -3}, 0.5f}, {{4, 0, -4}, 0.75f}};
  struct Odd {
    float x, v[3];
    int32_t k;
  } odd[kScalarInvocations];
  float s = 2.0f, off[3] = {0.25f, -0.5f, 1.0f}, k[2] = {1.5f, -3.0f}, m[2][3] = {{10, 20, 30}, {-10, -20, -30}};
  ScalarLayoutValues() {
    for (int i = 0; i < 8; ++i)
      for (int c = 0; c < 3; ++c) arr[i][c] = float(i * 3 + c) * 0.25f - 2.0f;
    for (uint32_t i = 0; i < kScalarInvocations; ++i)
      odd[i] = {float(i) * 0.5f, {float(i), -float(i) * 0.25f, 1.0f}, int32_t(i * 7) - 20};
  }
};

inline void putFloats(std::vector<uint8_t>& b, size_t offset, const float* v, size_t n) {
  std::memcpy(b.data() + offset, v, n * 4);
}

inline std::vector<uint8_t> scalarInBlock(const ScalarLayoutValues& v) {
  std::vector<uint8_t> b(kScalarInBytes, 0xee);
  putFloats(b, 0, v.a, 3);
  putFloats(b, 12, &v.b, 1);
  for (int i = 0; i < 8; ++i) putFloats(b, 16 + 12 * i, v.arr[i], 3);
  putFloats(b, 112, &v.c, 1);
  putFloats(b, 116, v.v2, 2);
  for (int i = 0; i < 3; ++i) {
    putFloats(b, 124 + 16 * i, v.items[i].p, 3);
    putFloats(b, 124 + 16 * i + 12, &v.items[i].w, 1);
  }
  for (uint32_t i = 0; i < kScalarInvocations; ++i) {
    putFloats(b, 172 + 20 * i, &v.odd[i].x, 1);
    putFloats(b, 172 + 20 * i + 4, v.odd[i].v, 3);
    std::memcpy(b.data() + 172 + 20 * i + 16, &v.odd[i].k, 4);
  }
  return b;
}

inline std::vector<uint8_t> scalarUniformBlock(const ScalarLayoutValues& v) {
  std::vector<uint8_t> b(kScalarUniformBytes, 0xee);
  putFloats(b, 0, &v.s, 1);
  putFloats(b, 4, v.off, 3);
  putFloats(b, 16, v.k, 2);
  putFloats(b, 24, v.m[0], 3);
  putFloats(b, 36, v.m[1], 3);
  return b;
}

// The output block after the dispatch, when it was filled with `fill` bytes before.
inline std::vector<uint8_t> scalarExpectedOut(const ScalarLayoutValues& v, uint8_t fill) {
  std::vector<uint8_t> b(kScalarOutBytes, fill);
  for (uint32_t i = 0; i < kScalarInvocations; ++i) {
    float extra[3] = {v.b, v.c, v.items[i % 3].w};
    float r[3];
    for (int c = 0; c < 3; ++c) r[c] = v.arr[i][c] * v.s + v.off[c] + extra[c] + v.m[i % 2][c];
    putFloats(b, 12 * i, r, 3);
    ScalarLayoutValues::Odd d = v.odd[i];
    d.x += v.a[0] + v.v2[1];
    for (int c = 0; c < 3; ++c) d.v[c] = d.v[c] * v.k[0] + v.items[i % 3].p[c];
    d.k = d.k * 2 + int32_t(i);
    putFloats(b, 100 + 20 * i, &d.x, 1);
    putFloats(b, 100 + 20 * i + 4, d.v, 3);
    std::memcpy(b.data() + 100 + 20 * i + 16, &d.k, 4);
  }
  float tail = v.a[1] + v.a[2] + v.v2[0] + v.k[1];
  putFloats(b, 96, &tail, 1);
  return b;
}

}  // namespace vkrt::testing
