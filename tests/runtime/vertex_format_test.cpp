// The vertex formats of acceleration structure builds: each decodes x, y and z from bytes written here by its
// format's definition (IEEE half, float and double; SNORM c / (2^(b-1) - 1) clamped to -1; UNORM c / (2^b - 1)),
// a fourth component is ignored, and stride and read sizes follow the component size.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "runtime/acceleration_structure_build.hpp"

namespace vkrt {
namespace {

template <class T>
std::vector<uint8_t> bytesOf(std::initializer_list<T> values) {
  std::vector<uint8_t> b(values.size() * sizeof(T));
  std::memcpy(b.data(), values.begin(), b.size());
  return b;
}

void expectDecoded(VkFormat f, const std::vector<uint8_t>& bytes, float x, float y, float z) {
  float out[3] = {9, 9, 9};
  decodeVertex(f, bytes.data(), out);
  EXPECT_FLOAT_EQ(out[0], x) << "format " << f;
  EXPECT_FLOAT_EQ(out[1], y) << "format " << f;
  EXPECT_FLOAT_EQ(out[2], z) << "format " << f;
}

TEST(VertexFormats, EveryAcceptedFormatDecodesByItsDefinition) {
  expectDecoded(VK_FORMAT_R32G32_SFLOAT, bytesOf<float>({1.5f, -2}), 1.5f, -2, 0);
  expectDecoded(VK_FORMAT_R32G32B32A32_SFLOAT, bytesOf<float>({1, 2, 3, 99}), 1, 2, 3);
  // Half floats: 0x3C00 = 1, 0xC000 = -2, 0x3800 = 0.5.
  expectDecoded(VK_FORMAT_R16G16B16_SFLOAT, bytesOf<uint16_t>({0x3C00, 0xC000, 0x3800}), 1, -2, 0.5f);
  expectDecoded(VK_FORMAT_R16G16B16_SNORM, bytesOf<int16_t>({32767, -32768, 0}), 1, -1, 0);
  expectDecoded(VK_FORMAT_R16G16B16_UNORM, bytesOf<uint16_t>({65535, 0, 65535}), 1, 0, 1);
  expectDecoded(VK_FORMAT_R8G8B8_SNORM, bytesOf<int8_t>({127, -128, -127}), 1, -1, -1);
  expectDecoded(VK_FORMAT_R8G8B8A8_UNORM, bytesOf<uint8_t>({255, 51, 0, 7}), 1, 0.2f, 0);
  expectDecoded(VK_FORMAT_R64G64_SFLOAT, bytesOf<double>({0.25, -8}), 0.25f, -8, 0);
  expectDecoded(VK_FORMAT_R64G64B64_SFLOAT, bytesOf<double>({1, 2, 3}), 1, 2, 3);
  expectDecoded(VK_FORMAT_R64G64B64A64_SFLOAT, bytesOf<double>({-1, 0.5, 4, 100}), -1, 0.5f, 4);
}

TEST(VertexFormats, SizesAndTheFormatsThatAreNotAccepted) {
  EXPECT_EQ(vertexComponentBytes(VK_FORMAT_R8G8_UNORM), 1u);
  EXPECT_EQ(vertexReadBytes(VK_FORMAT_R8G8_UNORM), 2u) << "two components: a vertex of 2 bytes";
  EXPECT_EQ(vertexReadBytes(VK_FORMAT_R16G16B16A16_SFLOAT), 6u) << "w is not read";
  EXPECT_EQ(vertexComponentBytes(VK_FORMAT_R64G64B64_SFLOAT), 8u);
  EXPECT_EQ(vertexReadBytes(VK_FORMAT_R64G64B64A64_SFLOAT), 24u);
  for (VkFormat f : {VK_FORMAT_R32_SFLOAT, VK_FORMAT_R8_UNORM, VK_FORMAT_R32G32B32_UINT, VK_FORMAT_B8G8R8A8_UNORM,
                     VK_FORMAT_UNDEFINED})
    EXPECT_FALSE(accelerationStructureVertexFormat(f)) << "format " << f;
  EXPECT_TRUE(accelerationStructureVertexFormat(VK_FORMAT_R16G16B16_SNORM));
}

}  // namespace
}  // namespace vkrt
