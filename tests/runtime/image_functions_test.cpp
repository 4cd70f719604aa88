// The texel encoding and decoding behind the image functions compiled shaders call
// (runtime/image_functions.hpp), and those functions on null descriptors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "runtime/format.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt {
namespace {

float asFloat(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}
uint32_t asWord(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

TEST(ImageFunctions, DecodeNormalizedIntegerAndFloatFormats) {
  uint32_t w[4];
  const uint8_t rgba8[4] = {0, 51, 255, 128};
  decodeTexel(*formatInfo(VK_FORMAT_R8G8B8A8_UNORM), rgba8, w);
  EXPECT_EQ(asFloat(w[0]), 0.0f);
  EXPECT_FLOAT_EQ(asFloat(w[1]), 0.2f);
  EXPECT_EQ(asFloat(w[2]), 1.0f);
  EXPECT_FLOAT_EQ(asFloat(w[3]), 128.0f / 255.0f);
  // BGRA memory order comes back as RGBA.
  decodeTexel(*formatInfo(VK_FORMAT_B8G8R8A8_UNORM), rgba8, w);
  EXPECT_EQ(asFloat(w[0]), 1.0f);
  EXPECT_EQ(asFloat(w[2]), 0.0f);
  // SNORM: -128 and -127 both decode to -1.
  const int8_t sn[4] = {-128, -127, 127, 0};
  decodeTexel(*formatInfo(VK_FORMAT_R8G8B8A8_SNORM), reinterpret_cast<const uint8_t*>(sn), w);
  EXPECT_EQ(asFloat(w[0]), -1.0f);
  EXPECT_EQ(asFloat(w[1]), -1.0f);
  EXPECT_EQ(asFloat(w[2]), 1.0f);
  // One-component formats fill G = B = 0, A = 1 (1.0 for floats, 1 for integers).
  const int32_t si = -7;
  decodeTexel(*formatInfo(VK_FORMAT_R32_SINT), reinterpret_cast<const uint8_t*>(&si), w);
  EXPECT_EQ(int32_t(w[0]), -7);
  EXPECT_EQ(w[1], 0u);
  EXPECT_EQ(w[3], 1u);
  const uint16_t half = 0xC140;  // -2.625
  decodeTexel(*formatInfo(VK_FORMAT_R16_SFLOAT), reinterpret_cast<const uint8_t*>(&half), w);
  EXPECT_EQ(asFloat(w[0]), -2.625f);
  EXPECT_EQ(asFloat(w[3]), 1.0f);
  // sRGB: 188 is about 0.5 linear; alpha stays linear.
  const uint8_t srgb[4] = {188, 0, 255, 188};
  decodeTexel(*formatInfo(VK_FORMAT_R8G8B8A8_SRGB), srgb, w);
  EXPECT_NEAR(asFloat(w[0]), std::pow((188 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
  EXPECT_FLOAT_EQ(asFloat(w[3]), 188.0f / 255.0f);
  // A2B10G10R10: R in the low bits.
  const uint32_t packed = 1023u | (512u << 10) | (0u << 20) | (3u << 30);
  decodeTexel(*formatInfo(VK_FORMAT_A2B10G10R10_UNORM_PACK32), reinterpret_cast<const uint8_t*>(&packed), w);
  EXPECT_EQ(asFloat(w[0]), 1.0f);
  EXPECT_FLOAT_EQ(asFloat(w[1]), 512.0f / 1023.0f);
  EXPECT_EQ(asFloat(w[3]), 1.0f);
}

// 8-bit UNorm encodes f x 255 in float, rounded to nearest even: always one of the two integers nearest to the exact
// product ("Conversion from Floating-Point to Normalized Fixed-Point"), that integer itself where the exact product is
// one (0 and 1.0 included), and the exact product's nearest wherever the float product rounds to the same side. Over
// the floats nearest to each k / 255 and to each halfway (k + 0.5) / 255 with their neighbours, and a million random
// ones.
TEST(ImageFunctions, Unorm8EncodeIsOneOfTheTwoNearestIntegers) {
  auto encode = [](float f) {
    const uint32_t in[4] = {asWord(f), asWord(f), asWord(f), asWord(f)};
    uint8_t t[4];
    encodeTexel(*formatInfo(VK_FORMAT_R8G8B8A8_UNORM), in, t);
    return t[0];
  };
  auto check = [&](float f) {
    if (!(f >= 0.0f && f <= 1.0f)) return;
    const double exact = double(f) * 255.0;  // exact: 24 + 8 bits
    const uint8_t got = encode(f);
    ASSERT_TRUE(got == std::floor(exact) || got == std::ceil(exact)) << f << " " << exact << " " << int(got);
    ASSERT_EQ(got, uint8_t(std::nearbyint(f * 255.0f))) << f;  // the float product, nearest even
  };
  size_t differs = 0;  // from the exact product's nearest: only next to a halfway value
  for (int k = 0; k <= 255; ++k) {
    for (double at : {double(k), k + 0.5}) {
      float f = float(at / 255.0);
      for (int i = 0; i < 4; ++i) f = std::nextafter(f, 0.0f);
      for (int i = 0; i < 9; ++i, f = std::nextafter(f, 2.0f)) {
        check(f);
        if (f >= 0.0f && f <= 1.0f && encode(f) != uint8_t(std::nearbyint(double(f) * 255.0))) {
          ++differs;
          EXPECT_LT(std::fabs(double(f) * 255.0 - std::floor(double(f) * 255.0) - 0.5), 1e-4) << f;
        }
      }
    }
    EXPECT_EQ(encode(float(double(k) / 255.0)), k);  // the float nearest to k / 255 encodes as k
  }
  EXPECT_EQ(encode(0.0f), 0);
  EXPECT_EQ(encode(1.0f), 255);
  EXPECT_GT(differs, 0u);  // the float product does round some near-halfway values the other way
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000000; ++i) check(u(rng));
}

TEST(ImageFunctions, EncodeRoundsClampsAndRoundTrips) {
  uint8_t t[16] = {};
  uint32_t in[4] = {asWord(0.5f), asWord(-3.0f), asWord(7.0f), asWord(0.2f)};
  encodeTexel(*formatInfo(VK_FORMAT_R8G8B8A8_UNORM), in, t);
  EXPECT_EQ(t[0], 128);  // 127.5 rounds to even... to nearest: 128
  EXPECT_EQ(t[1], 0);
  EXPECT_EQ(t[2], 255);
  EXPECT_EQ(t[3], 51);
  uint32_t h[4] = {asWord(-2.625f), asWord(65504.0f), asWord(1.0f / 3.0f), asWord(0.0f)};
  encodeTexel(*formatInfo(VK_FORMAT_R16G16B16A16_SFLOAT), h, t);
  uint16_t hv[4];
  std::memcpy(hv, t, 8);
  EXPECT_EQ(hv[0], 0xC140);
  EXPECT_EQ(hv[1], 0x7BFF);
  EXPECT_EQ(hv[2], 0x3555);  // 1/3 rounded to nearest half
  uint32_t ints[4] = {0x12345678u, 0xFFFFFFFFu, 3u, 4u};
  encodeTexel(*formatInfo(VK_FORMAT_R16G16_UINT), ints, t);
  uint16_t iv[2];
  std::memcpy(iv, t, 4);
  EXPECT_EQ(iv[0], 0x5678);
  EXPECT_EQ(iv[1], 0xFFFF);
  // Every rgba32f word survives unchanged.
  uint32_t f[4] = {asWord(1.5f), asWord(-0.0f), 0x7F800000u, asWord(1e-30f)}, back[4];
  encodeTexel(*formatInfo(VK_FORMAT_R32G32B32A32_SFLOAT), f, t);
  decodeTexel(*formatInfo(VK_FORMAT_R32G32B32A32_SFLOAT), t, back);
  EXPECT_EQ(std::memcmp(f, back, 16), 0);
}

// The packed 16-bit formats of "Mandatory Format Support: Sub-Byte Components", fields as formats.adoc places them
// (most significant first in the name): every field at its maximum alone, then mixed values, then the encoder's
// rounding back to the same words.
TEST(ImageFunctions, PackedSixteenBitFormatsPlaceEachFieldAsTheSpecificationSays) {
  auto decode = [](VkFormat format, uint16_t word, float want[4]) {
    uint32_t w[4];
    decodeTexel(*formatInfo(format), reinterpret_cast<const uint8_t*>(&word), w);
    for (int c = 0; c < 4; ++c) EXPECT_FLOAT_EQ(asFloat(w[c]), want[c]) << format << " word " << word << " c " << c;
  };
  auto encode = [](VkFormat format, const float rgba[4]) {
    uint32_t in[4] = {asWord(rgba[0]), asWord(rgba[1]), asWord(rgba[2]), asWord(rgba[3])};
    uint8_t t[4] = {0xAA, 0xAA, 0xAA, 0xAA};
    encodeTexel(*formatInfo(format), in, t);
    EXPECT_EQ(t[2], 0xAA) << "a 2-byte texel writes 2 bytes";
    uint16_t w;
    std::memcpy(&w, t, 2);
    return w;
  };
  // R5G6B5_UNORM_PACK16: R in bits 11..15, G in 5..10, B in 0..4; no alpha (reads 1).
  {
    float r[4] = {1, 0, 0, 1}, g[4] = {0, 1, 0, 1}, b[4] = {0, 0, 1, 1};
    decode(VK_FORMAT_R5G6B5_UNORM_PACK16, 0xF800, r);
    decode(VK_FORMAT_R5G6B5_UNORM_PACK16, 0x07E0, g);
    decode(VK_FORMAT_R5G6B5_UNORM_PACK16, 0x001F, b);
    float mixed[4] = {10 / 31.0f, 33 / 63.0f, 7 / 31.0f, 1};
    decode(VK_FORMAT_R5G6B5_UNORM_PACK16, uint16_t(10 << 11 | 33 << 5 | 7), mixed);
    EXPECT_EQ(encode(VK_FORMAT_R5G6B5_UNORM_PACK16, mixed), uint16_t(10 << 11 | 33 << 5 | 7));
    const float half[4] = {0.5f, 0.5f, 2.0f, 0.0f};  // 15.5 -> 16 (nearest), 31.5 -> 32, B clamped to 31
    EXPECT_EQ(encode(VK_FORMAT_R5G6B5_UNORM_PACK16, half), uint16_t(16 << 11 | 32 << 5 | 31));
  }
  // B4G4R4A4_UNORM_PACK16: B in bits 12..15, G in 8..11, R in 4..7, A in 0..3.
  {
    float b[4] = {0, 0, 1, 0}, a[4] = {0, 0, 0, 1}, r[4] = {1, 0, 0, 0};
    decode(VK_FORMAT_B4G4R4A4_UNORM_PACK16, 0xF000, b);
    decode(VK_FORMAT_B4G4R4A4_UNORM_PACK16, 0x000F, a);
    decode(VK_FORMAT_B4G4R4A4_UNORM_PACK16, 0x00F0, r);
    float mixed[4] = {3 / 15.0f, 9 / 15.0f, 12 / 15.0f, 5 / 15.0f};
    decode(VK_FORMAT_B4G4R4A4_UNORM_PACK16, 0xC935, mixed);
    EXPECT_EQ(encode(VK_FORMAT_B4G4R4A4_UNORM_PACK16, mixed), 0xC935);
  }
  // A1R5G5B5_UNORM_PACK16: A in bit 15, R in 10..14, G in 5..9, B in 0..4.
  {
    float a[4] = {0, 0, 0, 1}, r[4] = {1, 0, 0, 0}, b[4] = {0, 0, 1, 0};
    decode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, 0x8000, a);
    decode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, 0x7C00, r);
    decode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, 0x001F, b);
    float mixed[4] = {17 / 31.0f, 4 / 31.0f, 30 / 31.0f, 1};
    decode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, uint16_t(0x8000 | 17 << 10 | 4 << 5 | 30), mixed);
    EXPECT_EQ(encode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, mixed), uint16_t(0x8000 | 17 << 10 | 4 << 5 | 30));
    const float lowAlpha[4] = {0, 0, 0, 0.49f};  // the 1-bit alpha: 0.49 rounds to 0, 0.51 to 1
    EXPECT_EQ(encode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, lowAlpha), 0);
    const float highAlpha[4] = {0, 0, 0, 0.51f};
    EXPECT_EQ(encode(VK_FORMAT_A1R5G5B5_UNORM_PACK16, highAlpha), 0x8000);
  }
}

// VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: component = mantissa * 2^(exponent - 24); encoding after
// EXT_texture_shared_exponent (the exponent of the largest component, raised when its mantissa rounds to 512).
TEST(ImageFunctions, SharedExponentDecodesAndRoundsToTheLargestComponentsExponent) {
  const VkFormat f = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32;
  auto word = [](uint32_t e, uint32_t r, uint32_t g, uint32_t b) { return e << 27 | b << 18 | g << 9 | r; };
  uint32_t w[4];
  uint32_t t = word(15, 256, 511, 1);  // 2^-9 per mantissa step
  decodeTexel(*formatInfo(f), reinterpret_cast<const uint8_t*>(&t), w);
  EXPECT_EQ(asFloat(w[0]), 0.5f);
  EXPECT_EQ(asFloat(w[1]), 511.0f / 512.0f);
  EXPECT_EQ(asFloat(w[2]), 1.0f / 512.0f);
  EXPECT_EQ(asFloat(w[3]), 1.0f);  // no alpha
  t = word(31, 511, 0, 0);         // the largest value: 511 * 2^7
  decodeTexel(*formatInfo(f), reinterpret_cast<const uint8_t*>(&t), w);
  EXPECT_EQ(asFloat(w[0]), 65408.0f);
  auto encode = [&](float r, float g, float b) {
    uint32_t in[4] = {asWord(r), asWord(g), asWord(b), asWord(1.0f)};
    uint32_t out = 0;
    encodeTexel(*formatInfo(f), in, reinterpret_cast<uint8_t*>(&out));
    return out;
  };
  EXPECT_EQ(encode(1.0f, 0.5f, 0.25f), word(16, 256, 128, 64));  // max 1: exponent 0 + 16, mantissas / 2^-8
  EXPECT_EQ(encode(1.999f, 0.0f, 0.0f), word(17, 256, 0, 0));    // 511.74 rounds to 512: exponent raised
  EXPECT_EQ(encode(1e10f, -3.0f, NAN), word(31, 511, 0, 0));     // clamped to 65408; negative and NaN to 0
  EXPECT_EQ(encode(0.0f, 0.0f, 0.0f), 0u);
  EXPECT_EQ(encode(3.0f, 0.001f, 1.5f), word(17, 384, 0, 192));  // 0.001 / 2^-7 = 0.128 rounds to 0
}

// A8B8G8R8_*_PACK32 (R in bits 0..7, A in 24..31) are the bytes of R8G8B8A8 on a little-endian host.
TEST(ImageFunctions, A8B8G8R8PackedFormatsDecodeAsTheirRgba8Bytes) {
  const uint32_t packed = 0x80FF3300u;  // A 0x80, B 0xFF, G 0x33, R 0x00
  uint32_t w[4];
  decodeTexel(*formatInfo(VK_FORMAT_A8B8G8R8_UNORM_PACK32), reinterpret_cast<const uint8_t*>(&packed), w);
  EXPECT_EQ(asFloat(w[0]), 0.0f);
  EXPECT_FLOAT_EQ(asFloat(w[1]), 0.2f);
  EXPECT_EQ(asFloat(w[2]), 1.0f);
  EXPECT_FLOAT_EQ(asFloat(w[3]), 128.0f / 255.0f);
  decodeTexel(*formatInfo(VK_FORMAT_A8B8G8R8_SINT_PACK32), reinterpret_cast<const uint8_t*>(&packed), w);
  EXPECT_EQ(int32_t(w[2]), -1);
  EXPECT_EQ(int32_t(w[3]), -128);
  decodeTexel(*formatInfo(VK_FORMAT_A8B8G8R8_SRGB_PACK32), reinterpret_cast<const uint8_t*>(&packed), w);
  EXPECT_NEAR(asFloat(w[1]), std::pow((0x33 / 255.0 + 0.055) / 1.055, 2.4), 1e-6);
  EXPECT_FLOAT_EQ(asFloat(w[3]), 128.0f / 255.0f);  // alpha stays linear
}

TEST(ImageFunctions, NullDescriptorsReadZerosAndIgnoreWrites) {
  abi::DescriptorRecord zero{};
  int32_t coord[4] = {0, 0, 0, 0};
  uint32_t out[4] = {1, 2, 3, 4};
  vkrt_image_read(&zero, coord, out);
  EXPECT_EQ(out[0] | out[1] | out[2] | out[3], 0u);
  vkrt_image_write(&zero, coord, out);
  float fc[4] = {0.5f, 0.5f, 0, 0};
  out[0] = 9;
  vkrt_image_sample(&zero, &zero, fc, 0.0f, out);
  EXPECT_EQ(out[0], 0u);
  // The depth-comparison, offset and gather forms alike (unwritten descriptors read zeros).
  const float d[4] = {0, 0, 0, 0};
  const int32_t off[4] = {1, -1, 0, 0};
  auto expectZeros = [&](const char* what) {
    EXPECT_EQ(out[0] | out[1] | out[2] | out[3], 0u) << what;
    out[0] = out[1] = out[2] = out[3] = 9;
  };
  out[0] = out[1] = out[2] = out[3] = 9;
  vkrt_image_sample_dref(&zero, &zero, fc, 0.0f, 0.5f, nullptr, out);
  expectZeros("sample_dref");
  vkrt_image_sample_grad_dref(&zero, &zero, fc, d, d, NAN, 0.5f, off, out);
  expectZeros("sample_grad_dref");
  vkrt_image_sample_offset(&zero, &zero, fc, 0.0f, off, out);
  expectZeros("sample_offset");
  vkrt_image_sample_grad_offset(&zero, &zero, fc, d, d, NAN, off, out);
  expectZeros("sample_grad_offset");
  vkrt_image_gather(&zero, &zero, fc, 1, out);
  expectZeros("gather");
  vkrt_image_gather_dref(&zero, &zero, fc, 0.5f, out);
  expectZeros("gather_dref");
  int32_t size[4];
  vkrt_image_size(&zero, 0, size);
  EXPECT_EQ(size[0], 0);
  EXPECT_EQ(vkrt_image_levels(&zero), 0);
  // Texel buffers alike.
  out[0] = 9;
  vkrt_texel_buffer_read(&zero, 0, out);
  EXPECT_EQ(out[0] | out[1] | out[2] | out[3], 0u);
  vkrt_texel_buffer_write(&zero, 0, out);
  EXPECT_EQ(vkrt_texel_buffer_texel(&zero, 0), nullptr);
  EXPECT_EQ(vkrt_texel_buffer_size(&zero), 0);
}

}  // namespace
}  // namespace vkrt
