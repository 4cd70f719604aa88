// Inputs and expected outputs of tests/shaders/dxc_compute.spvasm (the shape DXC gives an HLSL compute shader),
// shared by the unit and the end-to-end test.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace vkrt::testing {

struct DxcParams {  // cbuffer Params: the Offsets of the module
  uint32_t count;
  float scale;
  float bias[2];
  int32_t offs[4];
};
static_assert(offsetof(DxcParams, bias) == 8 && offsetof(DxcParams, offs) == 16);

constexpr uint32_t kDxcInvocations = 16, kDxcVectors = 16;

inline DxcParams dxcParams() { return {13, -1.5f, {0.25f, 10.0f}, {1, -3, 0, 0}}; }

// Raw: kDxcVectors x 4 words, float bit patterns of every sign plus -0.0 / INT_MIN.
inline std::vector<uint32_t> dxcRaw() {
  std::vector<uint32_t> w(kDxcVectors * 4);
  for (uint32_t k = 0; k < w.size(); ++k) {
    float f = (float(int(k * 37 % 23) - 11) * 0.375f) * (k % 3 == 0 ? -1.0f : 1.0f);
    std::memcpy(&w[k], &f, 4);
  }
  w[4 * 5] = 0x80000000u;      // -0.0f, and INT_MIN for the signed division
  w[4 * 7 + 2] = 0xfffffff1u;  // NaN as a float, -15 as an int
  return w;
}

// Out (float4 per element, prefilled with `outFill`) and Dst (2 words per element, prefilled with `dstFill`)
// after the dispatch, for image dimensions `dims`.
inline void dxcExpected(const DxcParams& p, const std::vector<uint32_t>& raw, const uint32_t dims[2], float outFill,
                        uint32_t dstFill, std::vector<float>* out, std::vector<uint32_t>* dst) {
  out->assign(kDxcVectors * 4, outFill);
  dst->assign(kDxcVectors * 2, dstFill);
  for (uint32_t tid = 0; tid < kDxcInvocations; ++tid) {
    if (tid >= p.count) continue;
    int32_t i = int32_t(tid) + p.offs[0];
    float add[4] = {p.bias[0], p.bias[1], float(dims[0]), float(dims[1])};
    for (int c = 0; c < 4; ++c) {
      float v;
      std::memcpy(&v, &raw[size_t(i) * 4 + c], 4);
      float sel = v < 0 ? -v : v;
      float prod = sel * p.scale;
      (*out)[size_t(i) * 4 + c] = prod + add[c];
    }
    (*dst)[size_t(i) * 2] = uint32_t(int32_t(raw[size_t(i) * 4]) / p.offs[1]);
    (*dst)[size_t(i) * 2 + 1] = uint32_t(int32_t(raw[size_t(i) * 4 + 2]) >> 3);
  }
}

inline void expectDxc(const float* out, const uint32_t* dst, const std::vector<float>& wantOut,
                      const std::vector<uint32_t>& wantDst) {
  for (size_t k = 0; k < wantOut.size(); ++k) {
    // A NaN's sign and payload after arithmetic are not defined by SPIR-V or Vulkan (NVIDIA's driver drops the
    // sign here): a NaN is expected to stay a NaN; every other value, to the bit.
    if (std::isnan(wantOut[k])) {
      EXPECT_TRUE(std::isnan(out[k])) << "Out[" << k / 4 << "]."
                                      << "xyzw"[k % 4] << ": got " << out[k];
      continue;
    }
    EXPECT_EQ(std::memcmp(&out[k], &wantOut[k], 4), 0) << "Out[" << k / 4 << "]."
                                                       << "xyzw"[k % 4] << ": got " << out[k] << " want " << wantOut[k];
  }
  for (size_t k = 0; k < wantDst.size(); ++k) EXPECT_EQ(dst[k], wantDst[k]) << "Dst word " << k;
}

}  // namespace vkrt::testing
