// Storage images read and written without a format (tests/shaders/compute_formatless_image.comp,
// formatless_raygen.rgen): the formats the tests bind, their texels decoded and encoded here from the
// specification's conversion rules ("Conversion from Normalized Fixed-Point to Floating-Point" and back, 16-bit
// floats by _Float16), and the texels the compute shader must leave; shared by the unit test
// (tests/spirv/formatless_image_test.cpp) and the end-to-end tests (tests/e2e/compute_image_test.cpp,
// trace_formatless_test.cpp).
#pragma once

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace vkrt::testing {

// How a format's components are stored.
enum class Encoding { UNorm8, Float16, Float32, UInt16, UInt32 };

struct StorageFormat {
  VkFormat format;
  const char* name;
  uint32_t components;  // in memory
  Encoding encoding;
  bool bgra;  // memory order B, G, R, A
  uint32_t texelSize() const {
    uint32_t bytes = encoding == Encoding::UNorm8                                    ? 1
                     : encoding == Encoding::Float16 || encoding == Encoding::UInt16 ? 2
                                                                                     : 4;
    return bytes * components;
  }
  bool isInteger() const { return encoding == Encoding::UInt16 || encoding == Encoding::UInt32; }
};

inline constexpr StorageFormat kRgba8{VK_FORMAT_R8G8B8A8_UNORM, "R8G8B8A8_UNORM", 4, Encoding::UNorm8, false};
inline constexpr StorageFormat kBgra8{VK_FORMAT_B8G8R8A8_UNORM, "B8G8R8A8_UNORM", 4, Encoding::UNorm8, true};
inline constexpr StorageFormat kRgba16f{VK_FORMAT_R16G16B16A16_SFLOAT, "R16G16B16A16_SFLOAT", 4, Encoding::Float16,
                                        false};
inline constexpr StorageFormat kRgba32f{VK_FORMAT_R32G32B32A32_SFLOAT, "R32G32B32A32_SFLOAT", 4, Encoding::Float32,
                                        false};
inline constexpr StorageFormat kR32f{VK_FORMAT_R32_SFLOAT, "R32_SFLOAT", 1, Encoding::Float32, false};
inline constexpr StorageFormat kR32ui{VK_FORMAT_R32_UINT, "R32_UINT", 1, Encoding::UInt32, false};
inline constexpr StorageFormat kRgba16ui{VK_FORMAT_R16G16B16A16_UINT, "R16G16B16A16_UINT", 4, Encoding::UInt16, false};
inline constexpr StorageFormat kRgba32ui{VK_FORMAT_R32G32B32A32_UINT, "R32G32B32A32_UINT", 4, Encoding::UInt32, false};

using Float4 = std::array<float, 4>;
using Uint4 = std::array<uint32_t, 4>;

// Component i of memory order as R, G, B, A index.
inline uint32_t rgbaIndex(const StorageFormat& f, uint32_t i) { return f.bgra && i < 3 ? 2 - i : i; }

// A texel as the shader reads it: components the format lacks are G = B = 0, A = 1.
inline Float4 decodeFloat(const StorageFormat& f, const uint8_t* t) {
  Float4 c{0, 0, 0, 1};
  for (uint32_t i = 0; i < f.components; ++i) {
    float v = 0;
    if (f.encoding == Encoding::UNorm8) {
      v = float(t[i]) / 255.0f;
    } else if (f.encoding == Encoding::Float16) {
      _Float16 h;
      std::memcpy(&h, t + 2 * i, 2);
      v = float(h);
    } else {
      std::memcpy(&v, t + 4 * i, 4);
    }
    c[rgbaIndex(f, i)] = v;
  }
  return c;
}
inline Uint4 decodeUint(const StorageFormat& f, const uint8_t* t) {
  Uint4 c{0, 0, 0, 1};
  for (uint32_t i = 0; i < f.components; ++i) {
    if (f.encoding == Encoding::UInt16) {
      uint16_t v;
      std::memcpy(&v, t + 2 * i, 2);
      c[i] = v;
    } else {
      std::memcpy(&c[i], t + 4 * i, 4);
    }
  }
  return c;
}

// A texel as the shader's write stores it: only the format's components; UNORM clamps to [0, 1] and rounds f x 255
// (vkrt: the product in float) to the nearest integer (the tests' values are never halfway), 16-bit floats round to
// nearest even.
inline void encodeFloat(const StorageFormat& f, const Float4& c, uint8_t* t) {
  for (uint32_t i = 0; i < f.components; ++i) {
    float v = c[rgbaIndex(f, i)];
    if (f.encoding == Encoding::UNorm8) {
      t[i] = uint8_t(std::nearbyint(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    } else if (f.encoding == Encoding::Float16) {
      _Float16 h = _Float16(v);
      std::memcpy(t + 2 * i, &h, 2);
    } else {
      std::memcpy(t + 4 * i, &v, 4);
    }
  }
}
inline void encodeUint(const StorageFormat& f, const Uint4& c, uint8_t* t) {
  for (uint32_t i = 0; i < f.components; ++i) {
    if (f.encoding == Encoding::UInt16) {
      uint16_t v = uint16_t(c[i]);
      std::memcpy(t + 2 * i, &v, 2);
    } else {
      std::memcpy(t + 4 * i, &c[i], 4);
    }
  }
}

// Deterministic input texels for `texels` texels of `f`, different for each `seed`: any byte for UNORM, binary
// fractions in [-2, 2) (exact in 16 and 32 bits) for floats, integers small enough that the shader's
// u * 3 + index fits 16 bits for 16-bit integers.
inline std::vector<uint8_t> inputTexels(const StorageFormat& f, uint32_t texels, uint32_t seed) {
  std::vector<uint8_t> bytes(size_t(texels) * f.texelSize());
  for (uint32_t t = 0; t < texels; ++t) {
    uint8_t* p = bytes.data() + size_t(t) * f.texelSize();
    for (uint32_t i = 0; i < f.components; ++i) {
      uint32_t k = (t * 4 + i) * 37 + seed * 101 + 11;
      switch (f.encoding) {
        case Encoding::UNorm8: p[i] = uint8_t(k); break;
        case Encoding::Float16: {
          _Float16 h = _Float16(float(int(k % 128) - 64) / 32.0f);
          std::memcpy(p + 2 * i, &h, 2);
          break;
        }
        case Encoding::Float32: {
          float v = float(int(k % 512) - 256) / 128.0f;
          std::memcpy(p + 4 * i, &v, 4);
          break;
        }
        case Encoding::UInt16: {
          uint16_t v = uint16_t(k % 1000);
          std::memcpy(p + 2 * i, &v, 2);
          break;
        }
        case Encoding::UInt32: {
          uint32_t v = k * 2654435761u;
          std::memcpy(p + 4 * i, &v, 4);
          break;
        }
      }
    }
  }
  return bytes;
}

// One texel buffer per binding of compute_formatless_image.comp, tightly packed rows of `width` texels.
struct FormatlessImages {
  const StorageFormat* src;
  const StorageFormat* dst;
  const StorageFormat* acc;
  const StorageFormat* ids;
};

// The texels compute_formatless_image.comp leaves in dst, acc and ids (each expected buffer starts as the input
// it replaces; every texel of a width x height dispatch is written).
inline void expectedFormatless(const FormatlessImages& f, uint32_t width, uint32_t height,
                               const std::vector<uint8_t>& src, std::vector<uint8_t>& dst, std::vector<uint8_t>& acc,
                               std::vector<uint8_t>& ids) {
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      const Float4 c = decodeFloat(*f.src, src.data() + i * f.src->texelSize());
      const Float4 offset{float(x) * 0.125f, float(y) * 0.0625f, 0.25f, -0.125f};
      const Float4 swapped{c[2], c[1], c[0], c[3]};
      Float4 d;
      for (int k = 0; k < 4; ++k) d[k] = swapped[k] * 0.5f + offset[k];
      encodeFloat(*f.dst, d, dst.data() + i * f.dst->texelSize());
      Float4 a = decodeFloat(*f.acc, acc.data() + i * f.acc->texelSize());
      for (int k = 0; k < 4; ++k) a[k] += c[k];
      encodeFloat(*f.acc, a, acc.data() + i * f.acc->texelSize());
      Uint4 u = decodeUint(*f.ids, ids.data() + i * f.ids->texelSize());
      for (int k = 0; k < 4; ++k) u[k] = u[k] * 3u + uint32_t(x + 8 * y);
      encodeUint(*f.ids, u, ids.data() + i * f.ids->texelSize());
    }
}

// Compares texels byte for byte, naming the format, texel and component of the first mismatches. With
// `halfUlp`, 16-bit floats may differ by one unit in the last place (a driver may round them toward zero).
inline void expectTexels(const StorageFormat& f, const std::vector<uint8_t>& got, const std::vector<uint8_t>& want,
                         const std::string& what, bool halfUlp = false) {
  ASSERT_EQ(got.size(), want.size()) << what;
  const uint32_t ts = f.texelSize(), cs = ts / f.components;
  int reported = 0;
  for (size_t t = 0; t < got.size() / ts && reported < 8; ++t)
    for (uint32_t i = 0; i < f.components; ++i) {
      const uint8_t* g = got.data() + t * ts + i * cs;
      const uint8_t* w = want.data() + t * ts + i * cs;
      if (std::memcmp(g, w, cs) == 0) continue;
      if (halfUlp && f.encoding == Encoding::Float16) {
        uint16_t a, b;
        std::memcpy(&a, g, 2);
        std::memcpy(&b, w, 2);
        if (std::abs(int(a) - int(b)) <= 1) continue;
      }
      uint64_t gv = 0, wv = 0;
      std::memcpy(&gv, g, cs);
      std::memcpy(&wv, w, cs);
      ADD_FAILURE() << what << " (" << f.name << "): texel " << t << " component " << i << ": got 0x" << std::hex << gv
                    << ", want 0x" << wv;
      ++reported;
    }
}

}  // namespace vkrt::testing
