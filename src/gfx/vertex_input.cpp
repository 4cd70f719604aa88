#include "gfx/vertex_input.hpp"

#include <array>
#include <cmath>
#include <cstring>

namespace vkrt::gfx {
namespace {

using VN = VertexNumeric;
using VL = VertexLayout;

// The first format of each group of VkFormat values and how the group's members differ. Groups of the 8-bit formats
// run UNORM, SNORM, USCALED, SSCALED, UINT, SINT, SRGB (SRGB is no vertex format); the 10-bit packed ones stop at SINT;
// the 16-bit ones end with SFLOAT instead of SRGB; the 32-bit ones are UINT, SINT, SFLOAT.
struct Group {
  VkFormat first;
  uint8_t components, bits;
  VL layout;
  bool thirtyTwo;  // UINT, SINT, SFLOAT only
};

constexpr Group kGroups[] = {
    {VK_FORMAT_R8_UNORM, 1, 8, VL::Plain, false},
    {VK_FORMAT_R8G8_UNORM, 2, 8, VL::Plain, false},
    {VK_FORMAT_R8G8B8_UNORM, 3, 8, VL::Plain, false},
    {VK_FORMAT_B8G8R8_UNORM, 3, 8, VL::Bgra, false},
    {VK_FORMAT_R8G8B8A8_UNORM, 4, 8, VL::Plain, false},
    {VK_FORMAT_B8G8R8A8_UNORM, 4, 8, VL::Bgra, false},
    {VK_FORMAT_A8B8G8R8_UNORM_PACK32, 4, 8, VL::A8B8G8R8, false},
    {VK_FORMAT_A2R10G10B10_UNORM_PACK32, 4, 10, VL::A2R10G10B10, false},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 4, 10, VL::A2B10G10R10, false},
    {VK_FORMAT_R16_UNORM, 1, 16, VL::Plain, false},
    {VK_FORMAT_R16G16_UNORM, 2, 16, VL::Plain, false},
    {VK_FORMAT_R16G16B16_UNORM, 3, 16, VL::Plain, false},
    {VK_FORMAT_R16G16B16A16_UNORM, 4, 16, VL::Plain, false},
    {VK_FORMAT_R32_UINT, 1, 32, VL::Plain, true},
    {VK_FORMAT_R32G32_UINT, 2, 32, VL::Plain, true},
    {VK_FORMAT_R32G32B32_UINT, 3, 32, VL::Plain, true},
    {VK_FORMAT_R32G32B32A32_UINT, 4, 32, VL::Plain, true},
};

constexpr VkFormat kLast = VK_FORMAT_R32G32B32A32_SFLOAT;

std::array<VertexFormat, kLast + 1> buildTable() {
  std::array<VertexFormat, kLast + 1> t{};
  for (const Group& g : kGroups) {
    const int members = g.thirtyTwo ? 3 : g.bits == 10 ? 6 : 7;
    for (int m = 0; m < members; ++m) {
      VN n;
      if (g.thirtyTwo) {
        n = m == 0 ? VN::UInt : m == 1 ? VN::SInt : VN::SFloat;
      } else if (m == 6) {
        if (g.bits != 16) continue;  // SRGB
        n = VN::SFloat;
      } else {
        n = static_cast<VN>(m);  // UNorm, SNorm, UScaled, SScaled, UInt, SInt
      }
      VertexFormat& f = t[g.first + m];
      f.format = VkFormat(g.first + m);
      f.components = g.components;
      f.bits = g.bits;
      f.numeric = n;
      f.layout = g.layout;
      f.bytes = g.layout == VL::Plain || g.layout == VL::Bgra ? uint8_t(g.components * g.bits / 8) : 4;
    }
  }
  return t;
}

const std::array<VertexFormat, kLast + 1> kTable = buildTable();

float halfToFloat(uint16_t h) {
  const uint32_t sign = uint32_t(h >> 15) << 31;
  const uint32_t exp = (h >> 10) & 0x1F, mant = h & 0x3FF;
  float v;
  if (exp == 0) {
    v = std::ldexp(float(mant), -24);  // zero or subnormal
  } else if (exp == 31) {
    uint32_t bits = 0x7F800000u | (mant << 13);
    std::memcpy(&v, &bits, 4);
  } else {
    v = std::ldexp(float(mant | 0x400), int(exp) - 25);
  }
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  bits |= sign;
  std::memcpy(&v, &bits, 4);
  return v;
}

uint32_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

// Converts raw component `v` of `bits` bits.
uint32_t convertComponent(uint32_t v, uint32_t bits, VN n) {
  const uint32_t signBit = bits < 32 ? 1u << (bits - 1) : 0x80000000u;
  const int32_t s = bits < 32 ? int32_t((v ^ signBit) - signBit) : int32_t(v);
  switch (n) {
    case VN::UNorm:
      return floatBits(bits == 32 ? float(double(v) / 4294967295.0) : float(double(v) / double((1ull << bits) - 1)));
    case VN::SNorm: {
      const double d = double(s) / double((1ull << (bits - 1)) - 1);
      return floatBits(float(d < -1.0 ? -1.0 : d));
    }
    case VN::UScaled: return floatBits(float(v));
    case VN::SScaled: return floatBits(float(s));
    case VN::UInt: return v;
    case VN::SInt: return uint32_t(s);
    case VN::SFloat: return bits == 16 ? floatBits(halfToFloat(uint16_t(v))) : v;
  }
  return 0;
}

}  // namespace

const VertexFormat* vertexFormat(VkFormat format) {
  if (format < 0 || format > kLast) return nullptr;
  const VertexFormat& f = kTable[format];
  return f.components ? &f : nullptr;
}

void convertVertexAttribute(const VertexFormat& f, const uint8_t* src, uint32_t out[4]) {
  uint32_t raw[4] = {0, 0, 0, 0};
  uint32_t bits[4] = {f.bits, f.bits, f.bits, f.bits};
  switch (f.layout) {
    case VL::Plain:
    case VL::Bgra: {
      const uint32_t bytes = f.bits / 8;
      for (uint32_t c = 0; c < f.components; ++c) {
        uint32_t v = 0;
        std::memcpy(&v, src + c * bytes, bytes);  // little-endian host
        raw[c] = v;
      }
      if (f.layout == VL::Bgra) std::swap(raw[0], raw[2]);
      break;
    }
    case VL::A8B8G8R8: {
      uint32_t w;
      std::memcpy(&w, src, 4);
      for (int c = 0; c < 4; ++c) raw[c] = (w >> (8 * c)) & 0xFF;
      break;
    }
    case VL::A2R10G10B10:
    case VL::A2B10G10R10: {
      uint32_t w;
      std::memcpy(&w, src, 4);
      const uint32_t low = w & 0x3FF, mid = (w >> 10) & 0x3FF, high = (w >> 20) & 0x3FF;
      raw[0] = f.layout == VL::A2B10G10R10 ? low : high;
      raw[1] = mid;
      raw[2] = f.layout == VL::A2B10G10R10 ? high : low;
      raw[3] = w >> 30;
      bits[3] = 2;
      break;
    }
  }
  for (uint32_t c = 0; c < 4; ++c) {
    if (c < f.components) {
      out[c] = convertComponent(raw[c], bits[c], f.numeric);
    } else {
      out[c] = c == 3 ? (f.integer() ? 1u : floatBits(1.0f)) : 0u;
    }
  }
}

void fetchAttribute(const AttributeFetch& a, uint32_t vertexIndex, uint32_t instanceIndex, uint32_t* inputs) {
  uint32_t* out = inputs + 4 * a.location;
  const uint64_t index = a.perInstance ? instanceIndex : vertexIndex;
  const uint64_t at = index * a.stride + a.offset;
  if (!a.base || at > a.size || a.size - at < a.format->bytes) {
    out[0] = out[1] = out[2] = out[3] = 0;
    return;
  }
  convertVertexAttribute(*a.format, a.base + at, out);
}

}  // namespace vkrt::gfx
