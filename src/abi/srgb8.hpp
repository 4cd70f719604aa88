// 8-bit sRGB components, the runtime's codecs, the raster's quad writes and compiled code alike: the decode table
// (byte -> linear float) and the encode (linear float -> byte) as a search in a table of thresholds, exact for every
// float: the byte whose value is nearest to the Khronos Data Format Specification's sRGB encoding of the float
// ("sRGB EOTF" inverse: 12.92 x below 0.0031308, else 1.055 x^(1/2.4) - 0.055, times 255), computed in double when
// the table is built, so the same on every CPU (no float pow, whose last bit depends on the C library's choice of
// code for the CPU) and a few table reads instead of a pow per component.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace vkrt::abi {

struct Srgb8Tables {
  // Linear floats from [2^-13, 1) fall in 13 binades of 128 buckets each (the float's exponent and the top 7 bits of
  // its mantissa): `bucket` holds the byte of a bucket's first float, and no bucket holds more than one threshold
  // (the smallest gap between thresholds, near 1, is 2.3 buckets), so a float's byte is its bucket's or the next.
  static constexpr int kMinExponent = -13;  // below 2^-13 (1.2e-4) every float encodes to 0: threshold[1] is 1.5e-4
  static constexpr uint32_t kBuckets = 13 * 128;
  float decode[256];     // byte -> linear, as the runtime decodes it (the byte / 255 in float, then the EOTF in float)
  float threshold[257];  // [k]: the smallest float that encodes to k (k = 1..255); [0] 0, [256] +infinity
  uint8_t bucket[kBuckets];  // the byte of the bucket's first float

  Srgb8Tables() {
    for (uint32_t i = 0; i < 256; ++i) {
      const float c = float(double(i) / 255.0);
      decode[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
    // The exact encoding in double: 255 s(x), rounded; threshold k is where it reaches k - 1/2.
    auto scaled = [](float x) {
      const double d = x;
      return 255.0 * (d <= 0.0031308 ? 12.92 * d : 1.055 * std::pow(d, 1.0 / 2.4) - 0.055);
    };
    threshold[0] = 0.0f;
    threshold[256] = INFINITY;
    for (int k = 1; k < 256; ++k) {
      // From the inverse's estimate, float step by float to the first one at or past k - 1/2.
      const double y = (k - 0.5) / 255.0;
      float x = float(y <= 0.04045 ? y / 12.92 : std::pow((y + 0.055) / 1.055, 2.4));
      while (x > 0.0f && scaled(std::nextafter(x, 0.0f)) >= k - 0.5) x = std::nextafter(x, 0.0f);
      while (scaled(x) < k - 0.5) x = std::nextafter(x, 2.0f);
      threshold[k] = x;
    }
    int k = 0;  // the buckets' first floats increase: each bucket's byte starts from the previous one's
    for (uint32_t b = 0; b < kBuckets; ++b) {
      const float first = std::ldexp(1.0f + float(b % 128) / 128.0f, int(b / 128) + kMinExponent);
      while (k < 255 && threshold[k + 1] <= first) ++k;
      bucket[b] = uint8_t(k);
    }
  }

  // The byte of linear `x`: NaN and below 2^-13 (negatives included) 0, 1 and above 255.
  __attribute__((always_inline)) uint32_t encode(float x) const {
    if (!(x >= 0x1p-13f)) return 0;
    if (x >= 1.0f) return 255;
    uint32_t bits;
    std::memcpy(&bits, &x, 4);
    const uint32_t k = bucket[(bits >> 16) - ((127u + kMinExponent) << 7)];
    return k + (x >= threshold[k + 1] ? 1 : 0);
  }
};

// The tables, built once per process (on first use).
inline const Srgb8Tables& srgb8Tables() {
  static const Srgb8Tables tables;
  return tables;
}

}  // namespace vkrt::abi
