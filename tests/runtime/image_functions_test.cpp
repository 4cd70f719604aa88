// The texel encoding and decoding behind the image functions compiled shaders call
// (runtime/image_functions.hpp), and those functions on null descriptors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

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
