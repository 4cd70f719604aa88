// The quad writes' 8-bit sRGB encode (raster/backend.cpp srgbEncode4 and the AVX2 copy's srgbEncode8: float
// arithmetic, the table where it cannot decide) against abi::Srgb8Tables::encode (tests/runtime/srgb8_test.cpp checks
// it against the exact curve): every float of [2^-13, 1), where the arithmetic decides, and the floats around it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "abi/srgb8.hpp"
#include "raster/internal.hpp"

namespace vkrt::raster::test {
namespace {

TEST(RasterSrgb8, VectorEncodeIsTheTablesForEveryFloat) {
  const abi::Srgb8Tables& t = abi::srgb8Tables();
  constexpr uint32_t kFirst = 0x39000000u, kEnd = 0x3F800000u;  // 2^-13 and 1.0 as bits
  constexpr uint32_t kChunk = 1u << 20;
  std::vector<float> in(kChunk);
  std::vector<uint32_t> out(kChunk);
  uint64_t checked = 0;
  int mismatches = 0;
  for (uint32_t start = kFirst; start < kEnd; start += kChunk) {
    const uint32_t n = std::min(kChunk, kEnd - start);
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t bits = start + i;
      std::memcpy(&in[i], &bits, 4);
    }
    detail::encodeSrgb8Quads(in.data(), out.data(), n);
    std::vector<uint32_t> octets(n);
    const bool avx2 = detail::encodeSrgb8Octets(in.data(), octets.data(), n);
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t want = t.encode(in[i]);
      if (out[i] != want && ++mismatches <= 5) ADD_FAILURE() << in[i] << ": " << out[i] << ", the table " << want;
      if (avx2 && octets[i] != want && ++mismatches <= 5)
        ADD_FAILURE() << in[i] << ": " << octets[i] << " (AVX2 copy), the table " << want;
    }
    checked += n;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(checked, uint64_t(kEnd - kFirst));
}

TEST(RasterSrgb8, VectorEncodeOutsideTheCurve) {
  const abi::Srgb8Tables& t = abi::srgb8Tables();
  std::vector<float> in = {std::nanf(""), -std::nanf(""),
                           -0.0f,         0.0f,
                           -1.0f,         -INFINITY,
                           INFINITY,      0x1p-149f,
                           0x1p-126f,     std::nextafter(0x1p-13f, 0.0f),
                           0x1p-13f,      1.0f,
                           1.5f,          3e38f,
                           0.0031308f,    std::nextafter(0.0031308f, 1.0f)};
  uint64_t s = 7;
  while (in.size() < 4096) {  // random bits: negatives, large values, subnormals, NaNs
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    const uint32_t bits = uint32_t(s >> 32);
    float f;
    std::memcpy(&f, &bits, 4);
    in.push_back(f);
  }
  std::vector<uint32_t> out(in.size()), octets(in.size());
  detail::encodeSrgb8Quads(in.data(), out.data(), in.size());
  const bool avx2 = detail::encodeSrgb8Octets(in.data(), octets.data(), in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    EXPECT_EQ(out[i], t.encode(in[i])) << in[i];
    if (avx2) {
      EXPECT_EQ(octets[i], t.encode(in[i])) << in[i] << " (AVX2 copy)";
    }
  }
}

}  // namespace
}  // namespace vkrt::raster::test
