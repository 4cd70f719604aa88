// abi/srgb8.hpp's 8-bit sRGB encode: the nearest byte to the exact encoding for every float, by thresholds, against
// the encoding computed here in long double (the Khronos Data Format Specification's curve); the decode table as the
// runtime decoded before it; and the runtime's codecs and clears taking it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "abi/srgb8.hpp"
#include "runtime/format.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt::testing {
namespace {

using abi::Srgb8Tables;

// 255 times the sRGB encoding of x in [0, 1], in long double.
long double scaled(float x) {
  const long double d = x;
  return 255.0L * (d <= 0.0031308L ? 12.92L * d : 1.055L * std::pow(d, 1.0L / 2.4L) - 0.055L);
}

// The byte nearest to it (NaN and below 0: 0; above 1: 255).
uint32_t nearest(float x) {
  if (!(x > 0.0f)) return 0;
  if (x >= 1.0f) return 255;
  return uint32_t(std::floor(scaled(x) + 0.5L));
}

TEST(Srgb8, EachThresholdIsTheFirstFloatOfItsByte) {
  const Srgb8Tables& t = abi::srgb8Tables();
  for (uint32_t k = 1; k < 256; ++k) {
    const float x = t.threshold[k], below = std::nextafter(x, 0.0f);
    EXPECT_EQ(t.encode(x), k) << k;
    EXPECT_EQ(t.encode(below), k - 1) << k;
    EXPECT_GE(scaled(x), k - 0.5L) << k;
    EXPECT_LT(scaled(below), k - 0.5L) << k;
    EXPECT_LT(t.threshold[k - 1], x);
  }
}

TEST(Srgb8, NoBucketHoldsTwoThresholds) {
  // encode reads one threshold after its bucket's byte: every bucket must start at most one byte below its end.
  const Srgb8Tables& t = abi::srgb8Tables();
  for (uint32_t b = 0; b < Srgb8Tables::kBuckets; ++b) {
    const float first = std::ldexp(1.0f + float(b % 128) / 128.0f, int(b / 128) + Srgb8Tables::kMinExponent);
    const float last = std::nextafter(
        b + 1 < Srgb8Tables::kBuckets
            ? std::ldexp(1.0f + float((b + 1) % 128) / 128.0f, int((b + 1) / 128) + Srgb8Tables::kMinExponent)
            : 1.0f,
        0.0f);
    EXPECT_EQ(t.bucket[b], nearest(first)) << b;
    EXPECT_LE(nearest(last) - nearest(first), 1u) << b;
  }
  EXPECT_EQ(nearest(std::nextafter(0x1p-13f, 0.0f)), 0u);  // below the buckets: 0
}

TEST(Srgb8, EncodeIsTheNearestByteForEveryKindOfFloat) {
  const Srgb8Tables& t = abi::srgb8Tables();
  // A million floats spread over [2^-14, 1] (every exponent), and each threshold's neighbours.
  uint64_t s = 42;
  int mismatches = 0;
  for (int i = 0; i < 1000000; ++i) {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    const uint32_t bits = 0x38800000u + uint32_t(s >> 33) % (0x3F800001u - 0x38800000u);  // [2^-14, 1]
    float x;
    std::memcpy(&x, &bits, 4);
    if (t.encode(x) != nearest(x) && ++mismatches <= 5) ADD_FAILURE() << x << ": " << t.encode(x);
  }
  for (uint32_t k = 1; k < 256; ++k) {
    float x = t.threshold[k];
    for (int n = 0; n < 8; ++n) x = std::nextafter(x, 0.0f);
    for (int n = 0; n < 16; ++n, x = std::nextafter(x, 2.0f))
      if (t.encode(x) != nearest(x) && ++mismatches <= 5) ADD_FAILURE() << x << ": " << t.encode(x);
  }
  EXPECT_EQ(mismatches, 0);
  // The edges: NaN, negatives and -0 to 0, 1 and beyond to 255, subnormals to 0.
  EXPECT_EQ(t.encode(std::nanf("")), 0u);
  EXPECT_EQ(t.encode(-0.0f), 0u);
  EXPECT_EQ(t.encode(-1.0f), 0u);
  EXPECT_EQ(t.encode(-INFINITY), 0u);
  EXPECT_EQ(t.encode(0x1p-140f), 0u);
  EXPECT_EQ(t.encode(1.0f), 255u);
  EXPECT_EQ(t.encode(std::nextafter(1.0f, 0.0f)), 255u);
  EXPECT_EQ(t.encode(2.0f), 255u);
  EXPECT_EQ(t.encode(INFINITY), 255u);
}

TEST(Srgb8, DecodeIsTheRuntimesCurveAndEncodeInvertsIt) {
  const Srgb8Tables& t = abi::srgb8Tables();
  for (uint32_t i = 0; i < 256; ++i) {
    const float c = float(double(i) / 255.0);
    const float want = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    EXPECT_EQ(t.decode[i], want) << i;
    EXPECT_EQ(t.encode(t.decode[i]), i) << i;
  }
}

TEST(Srgb8, TheRuntimesCodecsAndClearsTakeIt) {
  const Srgb8Tables& t = abi::srgb8Tables();
  const FormatInfo* f = formatInfo(VK_FORMAT_R8G8B8A8_SRGB);
  ASSERT_NE(f, nullptr);
  for (float v : {0.0f, 0.001f, 0.2140411f, 0.5f, 0.73f, 1.0f, -0.5f, 3.0f}) {
    // Alpha stays linear: times 255 in float, rounded to nearest even, as 8-bit UNorm.
    const float alpha = v < 0 ? 0.0f : v > 1 ? 1.0f : v;
    const uint32_t wantAlpha = uint32_t(std::nearbyint(alpha * 255.0f));
    uint32_t words[4];
    for (int c = 0; c < 4; ++c) std::memcpy(&words[c], &v, 4);
    uint8_t texel[4];
    encodeTexel(*f, words, texel);
    for (int c = 0; c < 3; ++c) EXPECT_EQ(texel[c], t.encode(v)) << v;
    EXPECT_EQ(texel[3], wantAlpha) << v;
    VkClearColorValue clear{};
    for (float& c : clear.float32) c = v;
    uint8_t cleared[4];
    ASSERT_TRUE(encodeClearColor(*f, clear, cleared));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(cleared[c], t.encode(v)) << v;
    EXPECT_EQ(cleared[3], wantAlpha) << v;
  }
}

}  // namespace
}  // namespace vkrt::testing
