// Vertex input: the format conversion table against the spec's formulas ("Fixed-Point Data Conversions", "16-Bit
// Floating-Point Numbers"), computed here from a reference description of each format; the attribute fetch (strides,
// offsets, input rates, robust out-of-range reads); the format table agreeing with runtime's VERTEX_BUFFER_BIT.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "gfx/vertex_input.hpp"
#include "runtime/format.hpp"

namespace vkrt::gfx {
namespace {

enum class Kind { UNorm, SNorm, UScaled, SScaled, UInt, SInt, SFloat };

// A reference description, written from the format's name.
struct Ref {
  VkFormat format;
  int components;
  int bits;  // per component (10-bit packs: R, G, B; A has 2)
  Kind kind;
  const char* order;  // memory order of the components ("RGBA", "BGRA"), or "PACK8" / "PACK_ARGB" / "PACK_ABGR"
};

const Ref kRefs[] = {
    {VK_FORMAT_R8_UNORM, 1, 8, Kind::UNorm, "R"},
    {VK_FORMAT_R8_SNORM, 1, 8, Kind::SNorm, "R"},
    {VK_FORMAT_R8_USCALED, 1, 8, Kind::UScaled, "R"},
    {VK_FORMAT_R8_SSCALED, 1, 8, Kind::SScaled, "R"},
    {VK_FORMAT_R8_UINT, 1, 8, Kind::UInt, "R"},
    {VK_FORMAT_R8_SINT, 1, 8, Kind::SInt, "R"},
    {VK_FORMAT_R8G8_UNORM, 2, 8, Kind::UNorm, "RG"},
    {VK_FORMAT_R8G8_SINT, 2, 8, Kind::SInt, "RG"},
    {VK_FORMAT_R8G8B8_SNORM, 3, 8, Kind::SNorm, "RGB"},
    {VK_FORMAT_B8G8R8_UNORM, 3, 8, Kind::UNorm, "BGR"},
    {VK_FORMAT_B8G8R8_UINT, 3, 8, Kind::UInt, "BGR"},
    {VK_FORMAT_R8G8B8A8_UNORM, 4, 8, Kind::UNorm, "RGBA"},
    {VK_FORMAT_R8G8B8A8_SNORM, 4, 8, Kind::SNorm, "RGBA"},
    {VK_FORMAT_R8G8B8A8_USCALED, 4, 8, Kind::UScaled, "RGBA"},
    {VK_FORMAT_R8G8B8A8_UINT, 4, 8, Kind::UInt, "RGBA"},
    {VK_FORMAT_R8G8B8A8_SINT, 4, 8, Kind::SInt, "RGBA"},
    {VK_FORMAT_B8G8R8A8_UNORM, 4, 8, Kind::UNorm, "BGRA"},
    {VK_FORMAT_B8G8R8A8_SSCALED, 4, 8, Kind::SScaled, "BGRA"},
    {VK_FORMAT_A8B8G8R8_UNORM_PACK32, 4, 8, Kind::UNorm, "PACK8"},
    {VK_FORMAT_A8B8G8R8_SNORM_PACK32, 4, 8, Kind::SNorm, "PACK8"},
    {VK_FORMAT_A8B8G8R8_UINT_PACK32, 4, 8, Kind::UInt, "PACK8"},
    {VK_FORMAT_A8B8G8R8_SINT_PACK32, 4, 8, Kind::SInt, "PACK8"},
    {VK_FORMAT_A2R10G10B10_UNORM_PACK32, 4, 10, Kind::UNorm, "PACK_ARGB"},
    {VK_FORMAT_A2R10G10B10_SNORM_PACK32, 4, 10, Kind::SNorm, "PACK_ARGB"},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 4, 10, Kind::UNorm, "PACK_ABGR"},
    {VK_FORMAT_A2B10G10R10_SNORM_PACK32, 4, 10, Kind::SNorm, "PACK_ABGR"},
    {VK_FORMAT_A2B10G10R10_USCALED_PACK32, 4, 10, Kind::UScaled, "PACK_ABGR"},
    {VK_FORMAT_A2B10G10R10_UINT_PACK32, 4, 10, Kind::UInt, "PACK_ABGR"},
    {VK_FORMAT_A2B10G10R10_SINT_PACK32, 4, 10, Kind::SInt, "PACK_ABGR"},
    {VK_FORMAT_R16_UNORM, 1, 16, Kind::UNorm, "R"},
    {VK_FORMAT_R16_SNORM, 1, 16, Kind::SNorm, "R"},
    {VK_FORMAT_R16_SFLOAT, 1, 16, Kind::SFloat, "R"},
    {VK_FORMAT_R16G16_SSCALED, 2, 16, Kind::SScaled, "RG"},
    {VK_FORMAT_R16G16_UINT, 2, 16, Kind::UInt, "RG"},
    {VK_FORMAT_R16G16B16_SFLOAT, 3, 16, Kind::SFloat, "RGB"},
    {VK_FORMAT_R16G16B16A16_UNORM, 4, 16, Kind::UNorm, "RGBA"},
    {VK_FORMAT_R16G16B16A16_SINT, 4, 16, Kind::SInt, "RGBA"},
    {VK_FORMAT_R16G16B16A16_SFLOAT, 4, 16, Kind::SFloat, "RGBA"},
    {VK_FORMAT_R32_UINT, 1, 32, Kind::UInt, "R"},
    {VK_FORMAT_R32_SINT, 1, 32, Kind::SInt, "R"},
    {VK_FORMAT_R32_SFLOAT, 1, 32, Kind::SFloat, "R"},
    {VK_FORMAT_R32G32_SFLOAT, 2, 32, Kind::SFloat, "RG"},
    {VK_FORMAT_R32G32B32_UINT, 3, 32, Kind::UInt, "RGB"},
    {VK_FORMAT_R32G32B32_SFLOAT, 3, 32, Kind::SFloat, "RGB"},
    {VK_FORMAT_R32G32B32A32_SINT, 4, 32, Kind::SInt, "RGBA"},
    {VK_FORMAT_R32G32B32A32_SFLOAT, 4, 32, Kind::SFloat, "RGBA"},
};

uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// IEEE 754 binary16 -> float, by the definition (sign, 5-bit exponent biased by 15, 10-bit fraction).
float half(uint32_t h) {
  const int sign = (h >> 15) & 1, e = (h >> 10) & 31, m = h & 1023;
  double v = e == 0 ? std::ldexp(m, -24) : e == 31 ? (m ? NAN : INFINITY) : std::ldexp(1024 + m, e - 25);
  return float(sign ? -v : v);
}

uint32_t expected(uint32_t raw, int bits, Kind k) {
  const int64_t s = raw >= (1ull << (bits - 1)) ? int64_t(raw) - int64_t(1ull << bits) : int64_t(raw);
  switch (k) {
    case Kind::UNorm: return bitsOf(float(double(raw) / double((1ull << bits) - 1)));
    case Kind::SNorm: return bitsOf(float(std::max(double(s) / double((1ull << (bits - 1)) - 1), -1.0)));
    case Kind::UScaled: return bitsOf(float(raw));
    case Kind::SScaled: return bitsOf(float(s));
    case Kind::UInt: return raw;
    case Kind::SInt: return uint32_t(int32_t(s));
    case Kind::SFloat: return bits == 16 ? bitsOf(half(raw)) : raw;
  }
  return 0;
}

TEST(GfxVertexFormat, TableMatchesRuntimeVertexBufferBit) {
  for (int f = 0; f <= 200; ++f) {
    const bool gfx = vertexFormat(VkFormat(f)) != nullptr;
    EXPECT_EQ(gfx, vertexBufferFormat(VkFormat(f))) << "format " << f;
    EXPECT_EQ(gfx, (bufferFormatFeatures(VkFormat(f)) & VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT) != 0) << "format " << f;
  }
  EXPECT_EQ(vertexFormat(VK_FORMAT_R8G8B8A8_SRGB), nullptr);
  EXPECT_EQ(vertexFormat(VK_FORMAT_R64_SFLOAT), nullptr);
  EXPECT_EQ(vertexFormat(VK_FORMAT_B10G11R11_UFLOAT_PACK32), nullptr);
}

TEST(GfxVertexFormat, ConversionMatchesTheSpecFormulas) {
  std::mt19937 rng(7);
  for (const Ref& r : kRefs) {
    const VertexFormat* f = vertexFormat(r.format);
    ASSERT_NE(f, nullptr) << r.format;
    const std::string order = r.order;
    const bool packed = order.rfind("PACK", 0) == 0;
    const int bytes = packed ? 4 : r.components * r.bits / 8;
    EXPECT_EQ(f->bytes, bytes) << r.format;
    for (int trial = 0; trial < 64; ++trial) {
      uint32_t raw[4] = {};
      uint8_t data[16] = {};
      int componentBits[4] = {r.bits, r.bits, r.bits, r.bits};
      if (order == "PACK_ARGB" || order == "PACK_ABGR") componentBits[3] = 2;
      for (int c = 0; c < r.components; ++c) {
        const uint64_t range = 1ull << componentBits[c];
        raw[c] = uint32_t(rng() % range);
        // Extremes often: 0, 1, max, the sign boundary.
        if (trial < 4)
          raw[c] = uint32_t(trial == 0 ? 0 : trial == 1 ? range - 1 : trial == 2 ? range / 2 : range / 2 + 1);
      }
      if (!packed) {
        for (int c = 0; c < r.components; ++c) {
          const int memIndex = int(order.find("RGBA"[c]));
          std::memcpy(data + memIndex * r.bits / 8, &raw[c], r.bits / 8);
        }
      } else {
        uint32_t word = 0;
        if (order == "PACK8") word = raw[0] | raw[1] << 8 | raw[2] << 16 | raw[3] << 24;
        if (order == "PACK_ABGR") word = raw[0] | raw[1] << 10 | raw[2] << 20 | raw[3] << 30;
        if (order == "PACK_ARGB") word = raw[2] | raw[1] << 10 | raw[0] << 20 | raw[3] << 30;
        std::memcpy(data, &word, 4);
      }
      uint32_t out[4] = {0xDEAD, 0xDEAD, 0xDEAD, 0xDEAD};
      convertVertexAttribute(*f, data, out);
      const bool integer = r.kind == Kind::UInt || r.kind == Kind::SInt;
      for (int c = 0; c < 4; ++c) {
        const uint32_t want = c < r.components ? expected(raw[c], componentBits[c], r.kind)
                              : c == 3         ? (integer ? 1u : bitsOf(1.0f))
                                               : 0u;
        if (r.kind == Kind::SFloat && c < r.components && std::isnan(half(raw[c])) && r.bits == 16) {
          float got;
          std::memcpy(&got, &out[c], 4);
          EXPECT_TRUE(std::isnan(got));
          continue;
        }
        EXPECT_EQ(out[c], want) << "format " << r.format << " component " << c << " raw " << raw[c];
      }
    }
  }
}

TEST(GfxVertexFormat, KnownValues) {
  uint32_t out[4];
  const uint8_t snorm[] = {0x80, 0x81, 0x7F, 0x00};
  convertVertexAttribute(*vertexFormat(VK_FORMAT_R8G8B8A8_SNORM), snorm, out);
  float f[4];
  std::memcpy(f, out, 16);
  EXPECT_EQ(f[0], -1.0f);  // -128 clamps to -1
  EXPECT_EQ(f[1], -1.0f);
  EXPECT_EQ(f[2], 1.0f);
  EXPECT_EQ(f[3], 0.0f);
  const uint16_t halves[] = {0x3C00, 0xC000, 0x7BFF, 0x0001};
  convertVertexAttribute(*vertexFormat(VK_FORMAT_R16G16B16A16_SFLOAT), reinterpret_cast<const uint8_t*>(halves), out);
  std::memcpy(f, out, 16);
  EXPECT_EQ(f[0], 1.0f);
  EXPECT_EQ(f[1], -2.0f);
  EXPECT_EQ(f[2], 65504.0f);
  EXPECT_EQ(f[3], std::ldexp(1.0f, -24));
  const uint8_t bgra[] = {0x00, 0x33, 0xFF, 0x66};
  convertVertexAttribute(*vertexFormat(VK_FORMAT_B8G8R8A8_UNORM), bgra, out);
  std::memcpy(f, out, 16);
  EXPECT_EQ(f[0], 1.0f);
  EXPECT_EQ(f[1], 0.2f);
  EXPECT_EQ(f[2], 0.0f);
  EXPECT_EQ(f[3], 0.4f);
}

TEST(GfxVertexFetch, StridesOffsetsRatesAndRobustness) {
  // Binding data: 4 vertices of {float x, uint16 a, uint16 b}, stride 8.
  std::vector<uint8_t> buf(32);
  for (int v = 0; v < 4; ++v) {
    const float x = 1.5f * float(v + 1);
    const uint16_t ab[2] = {uint16_t(100 + v), uint16_t(200 + v)};
    std::memcpy(buf.data() + 8 * v, &x, 4);
    std::memcpy(buf.data() + 8 * v + 4, ab, 4);
  }
  AttributeFetch pos{vertexFormat(VK_FORMAT_R32_SFLOAT), 2, buf.data(), buf.size(), 0, 8, false};
  AttributeFetch pair{vertexFormat(VK_FORMAT_R16G16_UINT), 5, buf.data(), buf.size(), 4, 8, false};
  uint32_t inputs[32 * 4] = {};
  fetchAttribute(pos, 2, 0, inputs);
  fetchAttribute(pair, 2, 0, inputs);
  EXPECT_EQ(inputs[8], bitsOf(4.5f));
  EXPECT_EQ(inputs[9], 0u);
  EXPECT_EQ(inputs[11], bitsOf(1.0f));
  EXPECT_EQ(inputs[20], 102u);
  EXPECT_EQ(inputs[21], 202u);
  EXPECT_EQ(inputs[22], 0u);
  EXPECT_EQ(inputs[23], 1u);
  // Per instance: the instance index selects the element.
  AttributeFetch inst = pos;
  inst.perInstance = true;
  fetchAttribute(inst, 0, 3, inputs);
  EXPECT_EQ(inputs[8], bitsOf(6.0f));
  // Stride 0: every vertex reads the first element.
  AttributeFetch still = pos;
  still.stride = 0;
  fetchAttribute(still, 1000, 0, inputs);
  EXPECT_EQ(inputs[8], bitsOf(1.5f));
  // Out of range (vertex 4 starts at byte 32 = the size; a range that ends inside the attribute): zeros.
  fetchAttribute(pos, 4, 0, inputs);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(inputs[8 + c], 0u);
  AttributeFetch shortRange = pair;
  shortRange.size = 8 * 3 + 6;  // vertex 3's pair needs bytes 28..31
  fetchAttribute(shortRange, 3, 0, inputs);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(inputs[20 + c], 0u);
  fetchAttribute(shortRange, 2, 0, inputs);
  EXPECT_EQ(inputs[20], 102u);
  // Nothing bound: zeros. A huge index does not wrap around.
  AttributeFetch none = pos;
  none.base = nullptr;
  fetchAttribute(none, 0, 0, inputs);
  EXPECT_EQ(inputs[8], 0u);
  fetchAttribute(pos, 0xFFFFFFFFu, 0, inputs);
  EXPECT_EQ(inputs[8], 0u);
}

}  // namespace
}  // namespace vkrt::gfx
