#include "runtime/image_copy.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "abi/srgb8.hpp"
#include "exec/thread_pool.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt {

VkBufferImageCopy2 regionInBlocks(const VkBufferImageCopy2& r, uint32_t block) {
  if (block == 1) return r;
  auto up = [block](uint32_t v) { return (v + block - 1) / block; };
  VkBufferImageCopy2 b = r;
  b.bufferRowLength = up(r.bufferRowLength);
  b.bufferImageHeight = up(r.bufferImageHeight);
  b.imageOffset = {r.imageOffset.x / int32_t(block), r.imageOffset.y / int32_t(block), r.imageOffset.z};
  b.imageExtent = {up(r.imageExtent.width), up(r.imageExtent.height), r.imageExtent.depth};
  return b;
}

VkDeviceSize bufferFootprint(const VkBufferImageCopy2& region, uint32_t texelSize, uint32_t block) {
  const VkBufferImageCopy2 r = regionInBlocks(region, block);
  VkDeviceSize rowLength = r.bufferRowLength ? r.bufferRowLength : r.imageExtent.width;
  VkDeviceSize imageHeight = r.bufferImageHeight ? r.bufferImageHeight : r.imageExtent.height;
  VkDeviceSize layers = r.imageSubresource.layerCount;
  VkDeviceSize lastRow =
      ((layers - 1) * r.imageExtent.depth + (r.imageExtent.depth - 1)) * imageHeight + (r.imageExtent.height - 1);
  return (lastRow * rowLength + r.imageExtent.width) * texelSize;
}

void copyBufferImage(const Image& image, uint8_t* buffer, const VkBufferImageCopy2& region, bool toImage) {
  // A compressed image row by row of blocks (Image::texel takes block coordinates).
  const VkBufferImageCopy2 r = regionInBlocks(region, image.formatInfo->block);
  const VkImageAspectFlags aspect = r.imageSubresource.aspectMask;
  const uint32_t t = aspectBufferTexelSize(image.format, aspect);
  const VkDeviceSize rowLength = r.bufferRowLength ? r.bufferRowLength : r.imageExtent.width;
  const VkDeviceSize imageHeight = r.bufferImageHeight ? r.bufferImageHeight : r.imageExtent.height;
  const size_t rowBytes = size_t(r.imageExtent.width) * t;
  // One aspect of a depth/stencil texel: texel by texel, at the aspect's byte, as many bytes as it has.
  const uint32_t at = aspect == VK_IMAGE_ASPECT_STENCIL_BIT ? aspectFormatInfo(image.format, aspect)->offset : 0;
  const uint32_t bytes = aspectImageBytes(image.format, aspect);
  const bool perTexel = aspect != VK_IMAGE_ASPECT_COLOR_BIT && (t != image.formatInfo->texelSize || bytes != t);
  const uint32_t height = r.imageExtent.height, depth = r.imageExtent.depth;
  auto copyRow = [&](uint64_t row) {
    const uint32_t y = uint32_t(row % height), z = uint32_t(row / height % depth), l = uint32_t(row / height / depth);
    uint8_t* b = buffer + r.bufferOffset + ((VkDeviceSize(l) * depth + z) * imageHeight + y) * rowLength * t;
    uint8_t* i = image.texel(r.imageSubresource.mipLevel, r.imageSubresource.baseArrayLayer + l,
                             uint32_t(r.imageOffset.x), uint32_t(r.imageOffset.y) + y, uint32_t(r.imageOffset.z) + z);
    if (perTexel) {
      for (uint32_t x = 0; x < r.imageExtent.width; ++x) {
        uint8_t* it = i + size_t(x) * image.pixelSize + at;
        uint8_t* bt = b + size_t(x) * t;
        if (toImage) {
          std::memcpy(it, bt, bytes);
        } else {
          std::memset(bt, 0, t);  // D24 depth: the top byte of the 32-bit word is 0
          std::memcpy(bt, it, bytes);
        }
      }
    } else if (toImage) {
      std::memmove(i, b, rowBytes);
    } else {
      std::memmove(b, i, rowBytes);
    }
  };
  const uint64_t rows = uint64_t(r.imageSubresource.layerCount) * depth * height;
  // A large copy (a 1080p frame read back is 8 MB) in bands of rows on the thread pool: one thread's copy uses a
  // fraction of the memory bandwidth. The copy's source and destination memory may not overlap ("Copying Data
  // Between Buffers and Images"), so the rows are independent.
  constexpr uint64_t kBandBytes = uint64_t(256) << 10;
  const uint64_t bandRows = std::max<uint64_t>(1, kBandBytes / std::max<uint64_t>(rowBytes, 1));
  const uint64_t bands = (rows + bandRows - 1) / bandRows;
  if (bands <= 1) {
    for (uint64_t row = 0; row < rows; ++row) copyRow(row);
    return;
  }
  exec::ThreadPool::instance().parallelFor(bands, [&](uint64_t band, unsigned) {
    for (uint64_t row = band * bandRows; row < std::min(rows, (band + 1) * bandRows); ++row) copyRow(row);
  });
}

void copyImageImage(const Image& src, const Image& dst, const VkImageCopy2& region) {
  // In elements, texels or blocks: as many on both sides (one block of a compressed side for one texel of an
  // uncompressed side, "Copying Data Between Images").
  const uint32_t sb = src.formatInfo->block, db = dst.formatInfo->block;
  VkImageCopy2 r = region;
  r.srcOffset = {region.srcOffset.x / int32_t(sb), region.srcOffset.y / int32_t(sb), region.srcOffset.z};
  r.dstOffset = {region.dstOffset.x / int32_t(db), region.dstOffset.y / int32_t(db), region.dstOffset.z};
  r.extent = {(region.extent.width + sb - 1) / sb, (region.extent.height + sb - 1) / sb, region.extent.depth};
  const size_t rowBytes = size_t(r.extent.width) * src.pixelSize;
  // One aspect of a combined depth/stencil format: only its bytes of each texel.
  const VkImageAspectFlags aspect = r.srcSubresource.aspectMask;
  const bool perTexel = (src.aspects & VK_IMAGE_ASPECT_DEPTH_BIT) && (src.aspects & VK_IMAGE_ASPECT_STENCIL_BIT) &&
                        aspect != (VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT);
  const uint32_t at = aspect == VK_IMAGE_ASPECT_STENCIL_BIT ? aspectFormatInfo(src.format, aspect)->offset : 0;
  const uint32_t bytes = aspectImageBytes(src.format, aspect);
  // Planes: the layers of a 2D/1D image, the depth slices of a 3D image (a 3D image copies to and from the
  // layers of a 2D array image slice by slice).
  const bool src3d = src.type == VK_IMAGE_TYPE_3D, dst3d = dst.type == VK_IMAGE_TYPE_3D;
  const uint32_t planes = src3d ? r.extent.depth : r.srcSubresource.layerCount;
  for (uint32_t p = 0; p < planes; ++p) {
    const uint32_t srcLayer = r.srcSubresource.baseArrayLayer + (src3d ? 0 : p);
    const uint32_t srcZ = uint32_t(r.srcOffset.z) + (src3d ? p : 0);
    const uint32_t dstLayer = r.dstSubresource.baseArrayLayer + (dst3d ? 0 : p);
    const uint32_t dstZ = uint32_t(r.dstOffset.z) + (dst3d ? p : 0);
    for (uint32_t y = 0; y < r.extent.height; ++y) {
      const uint8_t* s =
          src.texel(r.srcSubresource.mipLevel, srcLayer, uint32_t(r.srcOffset.x), uint32_t(r.srcOffset.y) + y, srcZ);
      uint8_t* d =
          dst.texel(r.dstSubresource.mipLevel, dstLayer, uint32_t(r.dstOffset.x), uint32_t(r.dstOffset.y) + y, dstZ);
      if (!perTexel) {
        std::memmove(d, s, rowBytes);
        continue;
      }
      for (uint32_t x = 0; x < r.extent.width * src.samples; ++x)
        std::memmove(d + size_t(x) * src.formatInfo->texelSize + at, s + size_t(x) * src.formatInfo->texelSize + at,
                     bytes);
    }
  }
}

uint32_t floatToUnsignedSmallFloat(float f, int mantissaBits) {
  const uint32_t expMax = 31;
  if (std::isnan(f)) return (expMax << mantissaBits) | 1u;
  if (!(f > 0.0f)) return 0;  // negative values and zero clamp to zero
  if (std::isinf(f)) return expMax << mantissaBits;
  int e = 0;
  float m = std::frexp(f, &e);  // f = m * 2^e, m in [0.5, 1)
  int biased = e - 1 + 15;
  const uint32_t one = 1u << mantissaBits;
  if (biased <= 0) {
    // Denormal: value = M / 2^mantissaBits * 2^-14.
    uint32_t mant = uint32_t(std::nearbyint(std::ldexp(f, 14 + mantissaBits)));
    return mant;  // mant == one rolls into the smallest normal exponent by itself
  }
  uint32_t mant = uint32_t(std::nearbyint((2.0f * m - 1.0f) * float(one)));
  if (mant == one) {
    mant = 0;
    ++biased;
  }
  if (biased >= int(expMax)) return ((expMax - 1) << mantissaBits) | (one - 1);  // largest finite
  return (uint32_t(biased) << mantissaBits) | mant;
}

uint16_t floatToHalf(float f) {
  uint16_t sign = std::signbit(f) ? 0x8000 : 0;
  if (std::isnan(f)) return 0x7e00;
  float a = std::fabs(f);
  if (std::isinf(a) || a >= 65520.0f) return sign | 0x7c00;  // overflow rounds to infinity
  return sign | uint16_t(floatToUnsignedSmallFloat(a, 10));
}

namespace {

uint32_t unorm(float f, int bits) {
  float c = std::isnan(f) ? 0.0f : std::clamp(f, 0.0f, 1.0f);
  return uint32_t(std::nearbyint(c * float((1ull << bits) - 1)));
}

uint32_t snorm(float f, int bits) {
  float c = std::isnan(f) ? 0.0f : std::clamp(f, -1.0f, 1.0f);
  int32_t v = int32_t(std::nearbyint(c * float((1ll << (bits - 1)) - 1)));
  return uint32_t(v) & uint32_t((1ull << bits) - 1);
}

float linearToSrgb(float l) {
  l = std::isnan(l) ? 0.0f : std::clamp(l, 0.0f, 1.0f);
  return l <= 0.0031308f ? l * 12.92f : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

bool encodeClearColor(const FormatInfo& fi, const VkClearColorValue& color, uint8_t* texel) {
  std::memset(texel, 0, fi.texelSize);
  // Component c of memory order takes source channel src[c] (R,G,B,A = 0..3).
  static constexpr int kRgba[4] = {0, 1, 2, 3};
  static constexpr int kBgra[4] = {2, 1, 0, 3};
  const int* src = fi.bgr ? kBgra : kRgba;
  // Packed formats through the texel encoder (16- and 32-bit words, shared exponent): the clear color's words are
  // what a shader would write.
  if (fi.packed) {
    encodeTexel(fi, color.uint32, texel);
    return true;
  }
  uint8_t* out = texel;
  for (int c = 0; c < fi.components; ++c) {
    const int ch = src[c];
    const int bits = fi.bits[c];
    uint64_t v = 0;
    switch (fi.type) {
      case NumericType::UNorm: v = unorm(color.float32[ch], bits); break;
      case NumericType::SNorm: v = snorm(color.float32[ch], bits); break;
      case NumericType::SRGB:
        // 8-bit components as every other 8-bit sRGB encode (abi/srgb8.hpp: the nearest byte, on every CPU).
        v = ch == 3     ? unorm(color.float32[ch], bits)
            : bits == 8 ? abi::srgb8Tables().encode(color.float32[ch])
                        : unorm(linearToSrgb(color.float32[ch]), bits);
        break;
      case NumericType::UInt: v = color.uint32[ch] & uint32_t((1ull << bits) - 1); break;
      case NumericType::SInt: v = uint32_t(color.int32[ch]) & uint32_t((1ull << bits) - 1); break;
      case NumericType::SFloat:
        if (bits == 32) {
          uint32_t u;
          std::memcpy(&u, &color.float32[ch], 4);
          v = u;
        } else {
          v = floatToHalf(color.float32[ch]);
        }
        break;
      case NumericType::UFloat: return false;
    }
    std::memcpy(out, &v, size_t(bits / 8));  // little-endian
    out += bits / 8;
  }
  return true;
}

void clearImage(const Image& image, const uint8_t* texel, const VkImageSubresourceRange& range) {
  const uint32_t t = image.formatInfo->texelSize;
  uint32_t levels =
      range.levelCount == VK_REMAINING_MIP_LEVELS ? image.mipLevels - range.baseMipLevel : range.levelCount;
  uint32_t layers =
      range.layerCount == VK_REMAINING_ARRAY_LAYERS ? image.arrayLayers - range.baseArrayLayer : range.layerCount;
  for (uint32_t m = range.baseMipLevel; m < range.baseMipLevel + levels; ++m) {
    const MipLayout& mip = image.mips[m];
    for (uint32_t l = range.baseArrayLayer; l < range.baseArrayLayer + layers; ++l) {
      uint8_t* p = image.data() + mip.offset + l * mip.arrayPitch;
      for (VkDeviceSize i = 0; i < mip.arrayPitch; i += t) std::memcpy(p + i, texel, t);
    }
  }
}

void encodeDepth(VkFormat format, float depth, uint8_t* texel) {
  depth = std::isnan(depth) ? 0.0f : depth;
  switch (format) {
    case VK_FORMAT_D16_UNORM: {
      const uint16_t v = uint16_t(std::nearbyint(double(std::clamp(depth, 0.0f, 1.0f)) * 65535.0));
      std::memcpy(texel, &v, 2);
      return;
    }
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT: {
      const uint32_t v = uint32_t(std::nearbyint(double(std::clamp(depth, 0.0f, 1.0f)) * 16777215.0));
      std::memcpy(texel, &v, 3);  // little-endian: bits 0..23, byte 3 (stencil) kept
      return;
    }
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: std::memcpy(texel, &depth, 4); return;
    default: return;
  }
}

void encodeStencil(VkFormat format, uint32_t stencil, uint8_t* texel) {
  switch (format) {
    case VK_FORMAT_S8_UINT: texel[0] = uint8_t(stencil); return;
    case VK_FORMAT_D24_UNORM_S8_UINT: texel[3] = uint8_t(stencil); return;
    case VK_FORMAT_D32_SFLOAT_S8_UINT: texel[4] = uint8_t(stencil); return;
    default: return;
  }
}

void clearDepthStencilImage(const Image& image, const VkClearDepthStencilValue& value,
                            const VkImageSubresourceRange& range) {
  const uint32_t t = image.formatInfo->texelSize;
  const bool depth = range.aspectMask & image.aspects & VK_IMAGE_ASPECT_DEPTH_BIT;
  const bool stencil = range.aspectMask & image.aspects & VK_IMAGE_ASPECT_STENCIL_BIT;
  const uint32_t levels =
      range.levelCount == VK_REMAINING_MIP_LEVELS ? image.mipLevels - range.baseMipLevel : range.levelCount;
  const uint32_t layers =
      range.layerCount == VK_REMAINING_ARRAY_LAYERS ? image.arrayLayers - range.baseArrayLayer : range.layerCount;
  for (uint32_t m = range.baseMipLevel; m < range.baseMipLevel + levels; ++m) {
    const MipLayout& mip = image.mips[m];
    for (uint32_t l = range.baseArrayLayer; l < range.baseArrayLayer + layers; ++l) {
      uint8_t* p = image.data() + mip.offset + l * mip.arrayPitch;
      for (VkDeviceSize i = 0; i < mip.arrayPitch; i += t) {
        if (depth) encodeDepth(image.format, value.depth, p + i);
        if (stencil) encodeStencil(image.format, value.stencil, p + i);
      }
    }
  }
}

}  // namespace vkrt
