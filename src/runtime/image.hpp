// VkImage.
//
// Memory layout (the same for VK_IMAGE_TILING_LINEAR and OPTIMAL): tightly packed texels, row after row,
// slice after slice; for each mip level all array layers, mip levels one after the other:
//   offset(mip, layer, x, y, z) = mipOffset[mip] + layer * arrayPitch[mip]
//                                 + z * depthPitch[mip] + y * rowPitch[mip] + x * texelSize
// A multisampled image (samples 4: 2D, one mip level, optimal tiling) keeps a pixel's samples consecutively, so
// `texelSize` above is texelSize * samples (Image::pixelSize), as raster::Surface addresses them.
// Depth/stencil formats keep their whole texel (format.hpp: D24_UNORM_S8_UINT 4 bytes with stencil in byte 3,
// D32_SFLOAT_S8_UINT 8 bytes with stencil in byte 4); every aspect's subresource layout is that of the texels.
// A compressed (BC) image is laid out the same way in 4x4 blocks: texelSize is the block's bytes, a row holds
// ceil(width / 4) blocks and a slice ceil(height / 4) rows ("Compressed Image Formats": a mip level smaller than a
// block takes a whole one), and texel() takes block coordinates; MipLayout::extent stays in texels.
// vkGetImageSubresourceLayout reports exactly these pitches, and the image functions compiled shaders call
// (runtime/image_functions.cpp) address texels the same way.
#pragma once

#include <atomic>
#include <vector>

#include "runtime/format.hpp"
#include "runtime/object.hpp"

namespace vkrt {

class Memory;

struct MipLayout {
  VkExtent3D extent;
  VkDeviceSize offset;  // of layer 0
  VkDeviceSize rowPitch;
  VkDeviceSize depthPitch;  // one slice
  VkDeviceSize arrayPitch;  // one layer (= depthPitch * depth)
};

class Image : public Object {
 public:
  using Handle = VkImage;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_IMAGE;

  Image(Device* dev, const VkImageCreateInfo& info, const FormatInfo* format);

  const VkImageType type;
  const VkFormat format;
  const FormatInfo* const formatInfo;
  const VkExtent3D extent;
  const uint32_t mipLevels;
  const uint32_t arrayLayers;
  const VkImageUsageFlags usage;
  // VkImageStencilUsageCreateInfo::stencilUsage for an image with a stencil aspect, else `usage` ("Image
  // Creation": the stencil aspect may only be used as stencilUsage says; the other aspects as `usage` says).
  const VkImageUsageFlags stencilUsage;
  const bool separateStencilUsage;  // created with VkImageStencilUsageCreateInfo (and a stencil aspect)
  const VkImageTiling tiling;
  const VkImageCreateFlags flags;
  const uint32_t samples;            // 1 or 4
  const uint32_t pixelSize;          // formatInfo->texelSize * samples
  const VkImageAspectFlags aspects;  // formatAspects(format)
  std::vector<MipLayout> mips;
  VkDeviceSize size = 0;  // bytes of all subresources
  // VkImageFormatListCreateInfo's formats (VK_KHR_image_format_list): when not empty, the only formats the image's
  // views may have (VUID-VkImageViewCreateInfo-pNext-01585).
  std::vector<VkFormat> viewFormats;

  Memory* memory = nullptr;
  VkDeviceSize memoryOffset = 0;

  // A swapchain's image (runtime/swapchain.cpp): its layout is tracked, as the layout the barriers that executed
  // last on a queue left it in, so that a present can check it is PRESENT_SRC_KHR. Other images' layouts are not.
  bool presentable = false;
  std::atomic<VkImageLayout> trackedLayout{VK_IMAGE_LAYOUT_UNDEFINED};

  // The usage every aspect of `aspectMask` allows: stencilUsage for the stencil aspect, usage for the others
  // (0: usage).
  VkImageUsageFlags usageOf(VkImageAspectFlags aspectMask) const {
    VkImageUsageFlags u = ~VkImageUsageFlags(0);
    if (aspectMask & VK_IMAGE_ASPECT_STENCIL_BIT) u &= stencilUsage;
    if (!aspectMask || (aspectMask & ~VkImageAspectFlags(VK_IMAGE_ASPECT_STENCIL_BIT))) u &= usage;
    return u;
  }

  uint8_t* data() const;
  // Address of texel (x, y, z) of (mip, layer) (its sample 0); of block (x, y) of slice z for a compressed image;
  // no bounds check.
  uint8_t* texel(uint32_t mip, uint32_t layer, uint32_t x, uint32_t y, uint32_t z) const {
    const MipLayout& m = mips[mip];
    return data() + m.offset + layer * m.arrayPitch + z * m.depthPitch + y * m.rowPitch + x * pixelSize;
  }

  static constexpr VkDeviceSize kAlignment = 64;
};

// The extent of `extent` at mip level `mip` (each dimension halved, at least 1).
VkExtent3D mipExtent(VkExtent3D extent, uint32_t mip);

}  // namespace vkrt
