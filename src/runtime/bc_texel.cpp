#include "runtime/bc_texel.hpp"

#include <cstring>

#include "runtime/bc_decode.hpp"
#include "runtime/srgb.hpp"

namespace vkrt {
namespace {

bc::Kind kindOf(VkFormat format) {
  switch (format) {
    case VK_FORMAT_BC1_RGB_UNORM_BLOCK:
    case VK_FORMAT_BC1_RGB_SRGB_BLOCK: return bc::Kind::BC1_RGB;
    case VK_FORMAT_BC1_RGBA_UNORM_BLOCK:
    case VK_FORMAT_BC1_RGBA_SRGB_BLOCK: return bc::Kind::BC1_RGBA;
    case VK_FORMAT_BC2_UNORM_BLOCK:
    case VK_FORMAT_BC2_SRGB_BLOCK: return bc::Kind::BC2;
    case VK_FORMAT_BC3_UNORM_BLOCK:
    case VK_FORMAT_BC3_SRGB_BLOCK: return bc::Kind::BC3;
    case VK_FORMAT_BC4_UNORM_BLOCK: return bc::Kind::BC4_UNORM;
    case VK_FORMAT_BC4_SNORM_BLOCK: return bc::Kind::BC4_SNORM;
    case VK_FORMAT_BC5_UNORM_BLOCK: return bc::Kind::BC5_UNORM;
    case VK_FORMAT_BC5_SNORM_BLOCK: return bc::Kind::BC5_SNORM;
    case VK_FORMAT_BC6H_UFLOAT_BLOCK: return bc::Kind::BC6H_UFLOAT;
    case VK_FORMAT_BC6H_SFLOAT_BLOCK: return bc::Kind::BC6H_SFLOAT;
    default: return bc::Kind::BC7;  // BC7_UNORM, BC7_SRGB
  }
}

}  // namespace

void decodeBcTexel(const FormatInfo& f, const uint8_t* block, uint32_t x, uint32_t y, uint32_t out[4]) {
  float texels[16][4];
  bc::decodeBlock(kindOf(f.format), block, texels);
  float c[4] = {texels[y * 4 + x][0], texels[y * 4 + x][1], texels[y * 4 + x][2], texels[y * 4 + x][3]};
  for (unsigned i = f.components; i < 3; ++i) c[i] = 0.0f;
  if (f.components < 4) c[3] = 1.0f;
  if (f.type == NumericType::SRGB)
    for (int i = 0; i < 3; ++i) c[i] = srgbToLinear(c[i]);
  std::memcpy(out, c, 16);
}

}  // namespace vkrt
