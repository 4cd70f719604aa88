// Inputs and expected outputs of tests/shaders/compute_nonuniform_buffers.comp (per-invocation indices into a
// storage-buffer array and a uniform-buffer array), shared by the unit and the end-to-end test.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace vkrt::testing {

struct NonUniformBuffers {
  static constexpr uint32_t kN = 16, kBuffers = 5;
  // Storage buffer k: {head = 0, v[kN + k]}, v[j] = 100 * k + j.
  std::vector<std::vector<uint32_t>> data;
  // Uniform buffer u: {multiplier added to written elements, xor operands, value added to the fourth output}.
  uint32_t params[3][4] = {{7, 0xf0, 0x0f, 11}, {9, 0x33, 0x55, 22}, {13, 0x1234, 0x4321, 33}};

  NonUniformBuffers() : data(kBuffers) {
    for (uint32_t k = 0; k < kBuffers; ++k) {
      data[k].assign(1 + kN + k, 0);
      for (uint32_t j = 0; j < kN + k; ++j) data[k][1 + j] = 100 * k + j;
    }
  }

  // `out`: the kN * 4 output words; `storage(k)`: storage buffer k's words after the dispatch.
  void expect(const uint32_t* out, const std::function<const uint32_t*(uint32_t)>& storage) const {
    std::vector<uint32_t> count(kBuffers, 0);
    for (uint32_t i = 0; i < kN; ++i) {
      uint32_t b = i * 7 % 5, u = (i + i / 3) % 3;
      ++count[b];
      EXPECT_EQ(out[i * 4], data[b][1 + i]) << "storage buffer " << b << " read by invocation " << i;
      EXPECT_EQ(out[i * 4 + 1], params[u][1] ^ params[u][2]) << "uniform buffer " << u << " read by invocation " << i;
      EXPECT_EQ(out[i * 4 + 2], kN + b) << "length() of storage buffer " << b;
      EXPECT_EQ(out[i * 4 + 3], params[i % 3][3] + b * 1000) << i;
    }
    for (uint32_t k = 0; k < kBuffers; ++k) {
      const uint32_t* got = storage(k);
      EXPECT_EQ(got[0], count[k]) << "atomic count in storage buffer " << k;
      for (uint32_t j = 0; j < kN + k; ++j) {
        bool written = j < kN && j * 7 % 5 == k;
        uint32_t u = (j + j / 3) % 3;
        EXPECT_EQ(got[1 + j], written ? data[k][1 + j] * 3 + params[u][0] : data[k][1 + j])
            << "buffer " << k << " element " << j;
      }
    }
  }
};

}  // namespace vkrt::testing
