#include "runtime/image_view.hpp"

#include <algorithm>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/format.hpp"
#include "runtime/image.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

VkImageSubresourceRange resolve(const VkImageSubresourceRange& r, const Image& img) {
  VkImageSubresourceRange out = r;
  if (out.levelCount == VK_REMAINING_MIP_LEVELS) out.levelCount = img.mipLevels - r.baseMipLevel;
  if (out.layerCount == VK_REMAINING_ARRAY_LAYERS) out.layerCount = img.arrayLayers - r.baseArrayLayer;
  return out;
}

VkImageUsageFlags viewUsage(const VkImageViewCreateInfo& info, const Image& img) {
  if (auto* u = findInChain<VkImageViewUsageCreateInfo>(info.pNext, VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO))
    return u->usage;
  return img.usageOf(info.subresourceRange.aspectMask);
}

}  // namespace

ImageView::ImageView(Device* dev, const VkImageViewCreateInfo& info, Image* img)
    : Object(kType, dev->instance, dev),
      image(img),
      viewType(info.viewType),
      format(info.format),
      components(info.components),
      range(resolve(info.subresourceRange, *img)),
      usage(viewUsage(info, *img)),
      quad(describeQuadView(*this)),
      store(describeStoreView(*this)) {}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Which view types an image of a given type supports (VUID-VkImageViewCreateInfo-subResourceRange-01021 and
// the table under VkImageViewCreateInfo).
bool viewTypeFits(VkImageType image, VkImageViewType view, VkImageCreateFlags flags) {
  switch (view) {
    case VK_IMAGE_VIEW_TYPE_1D:
    case VK_IMAGE_VIEW_TYPE_1D_ARRAY: return image == VK_IMAGE_TYPE_1D;
    case VK_IMAGE_VIEW_TYPE_2D:
    case VK_IMAGE_VIEW_TYPE_2D_ARRAY:
      return image == VK_IMAGE_TYPE_2D ||
             (image == VK_IMAGE_TYPE_3D && (flags & VK_IMAGE_CREATE_2D_ARRAY_COMPATIBLE_BIT));
    case VK_IMAGE_VIEW_TYPE_CUBE:
    case VK_IMAGE_VIEW_TYPE_CUBE_ARRAY:
      return image == VK_IMAGE_TYPE_2D && (flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT);
    case VK_IMAGE_VIEW_TYPE_3D: return image == VK_IMAGE_TYPE_3D;
    default: return false;
  }
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateImageView(VkDevice device, const VkImageViewCreateInfo* pCreateInfo,
                                                    const VkAllocationCallbacks* pAllocator, VkImageView* pView) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Image* img = fromHandle<Image>(pCreateInfo->image);
  if (!img) {
    report(dev, Severity::Error, "VUID-VkImageViewCreateInfo-image-parameter",
           "vkCreateImageView: image 0x%llx is not a live VkImage", (unsigned long long)rawHandle(pCreateInfo->image));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const VkImageSubresourceRange& r = pCreateInfo->subresourceRange;
  // VUID-VkImageViewCreateInfo-subresourceRange-01478 / 01718 / 01480 / 01719
  uint32_t levels = r.levelCount == VK_REMAINING_MIP_LEVELS ? img->mipLevels - std::min(r.baseMipLevel, img->mipLevels)
                                                            : r.levelCount;
  uint32_t layers = r.layerCount == VK_REMAINING_ARRAY_LAYERS
                        ? img->arrayLayers - std::min(r.baseArrayLayer, img->arrayLayers)
                        : r.layerCount;
  const char* rangeVuid = r.baseMipLevel >= img->mipLevels ? "VUID-VkImageViewCreateInfo-subresourceRange-01478"
                          : levels == 0 || uint64_t(r.baseMipLevel) + levels > img->mipLevels
                              ? "VUID-VkImageViewCreateInfo-subresourceRange-01718"
                          : r.baseArrayLayer >= img->arrayLayers ? "VUID-VkImageViewCreateInfo-subresourceRange-01480"
                          : layers == 0 || uint64_t(r.baseArrayLayer) + layers > img->arrayLayers
                              ? "VUID-VkImageViewCreateInfo-subresourceRange-01719"
                              : nullptr;
  if (rangeVuid) {
    report(img, Severity::Error, rangeVuid,
           "vkCreateImageView: levels [%u, +%u) and layers [%u, +%u) exceed the image's %u levels and %u layers",
           r.baseMipLevel, r.levelCount, r.baseArrayLayer, r.layerCount, img->mipLevels, img->arrayLayers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-imageViewType-04973: non-array views have one layer
  if ((pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_1D || pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_2D ||
       pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_3D) &&
      layers != 1) {
    report(img, Severity::Error, "VUID-VkImageViewCreateInfo-imageViewType-04973",
           "vkCreateImageView: a non-array view type %d covers %u layers", (int)pCreateInfo->viewType, layers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-viewType-01004: cube array views need the imageCubeArray feature
  if (pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_CUBE_ARRAY && !dev->enabled(Feature::imageCubeArray)) {
    report(img, Severity::Error, "VUID-VkImageViewCreateInfo-viewType-01004",
           "vkCreateImageView: VK_IMAGE_VIEW_TYPE_CUBE_ARRAY needs the imageCubeArray feature, which is not enabled");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-image-01003 (cube views need CUBE_COMPATIBLE), otherwise the view type table
  // (VUID-VkImageViewCreateInfo-subResourceRange-01021)
  if (!viewTypeFits(img->type, pCreateInfo->viewType, img->flags)) {
    bool cube =
        pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_CUBE || pCreateInfo->viewType == VK_IMAGE_VIEW_TYPE_CUBE_ARRAY;
    report(img, Severity::Error,
           cube && img->type == VK_IMAGE_TYPE_2D ? "VUID-VkImageViewCreateInfo-image-01003"
                                                 : "VUID-VkImageViewCreateInfo-subResourceRange-01021",
           "vkCreateImageView: view type %d is not compatible with image type %d (flags 0x%x)",
           (int)pCreateInfo->viewType, (int)img->type, img->flags);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-image-01019: without MUTABLE_FORMAT the view's format is the image's;
  // VUID-VkImageViewCreateInfo-image-01018: with it, a compatible format (uncompressed: the same texel size; BC: the
  // same BC class); VUID-VkImageViewCreateInfo-image-01583: with BLOCK_TEXEL_VIEW_COMPATIBLE also an uncompressed
  // format whose texel is the image's block (viewFormatCompatible)
  const FormatInfo* vf = formatInfo(pCreateInfo->format);
  bool mutableFormat = img->flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  const bool blockTexel = img->flags & VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT;
  if (pCreateInfo->format != img->format &&
      (!mutableFormat || !vf || !viewFormatCompatible(img->format, pCreateInfo->format, img->flags) ||
       !formatFeatures(pCreateInfo->format))) {
    report(img, Severity::Error,
           !mutableFormat ? "VUID-VkImageViewCreateInfo-image-01019"
           : blockTexel   ? "VUID-VkImageViewCreateInfo-image-01583"
                          : "VUID-VkImageViewCreateInfo-image-01018",
           "vkCreateImageView: format %d is not compatible with the image's format %d (flags 0x%x)",
           (int)pCreateInfo->format, (int)img->format, img->flags);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-image-07072: an uncompressed view of a block-texel-view-compatible image covers one
  // mip level and one layer (its texels are the level's blocks: runtime/image_functions.cpp levelExtent)
  if (blockTexel && vf && vf->block == 1 && (levels != 1 || layers != 1)) {
    report(img, Severity::Error, "VUID-VkImageViewCreateInfo-image-07072",
           "vkCreateImageView: the uncompressed format %d views %u levels and %u layers of a compressed image (format "
           "%d, VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT); it must view one of each",
           (int)pCreateInfo->format, levels, layers, (int)img->format);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-pNext-01585: an image created with a format list takes views of those formats only
  if (!img->viewFormats.empty() &&
      std::find(img->viewFormats.begin(), img->viewFormats.end(), pCreateInfo->format) == img->viewFormats.end()) {
    report(img, Severity::Error, "VUID-VkImageViewCreateInfo-pNext-01585",
           "vkCreateImageView: format %d is not among the %zu formats of the image's VkImageFormatListCreateInfo",
           (int)pCreateInfo->format, img->viewFormats.size());
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageViewCreateInfo-pNext-02662 / 02663 / 02664: VkImageViewUsageCreateInfo::usage is a subset of the
  // usage of the view's aspects (stencilUsage for the stencil aspect of an image with separate stencil usage)
  if (auto* u =
          findInChain<VkImageViewUsageCreateInfo>(pCreateInfo->pNext, VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO)) {
    const VkImageAspectFlags aspects = pCreateInfo->subresourceRange.aspectMask;
    const bool stencil = img->separateStencilUsage && (aspects & VK_IMAGE_ASPECT_STENCIL_BIT);
    const bool other = !img->separateStencilUsage || (aspects & ~VkImageAspectFlags(VK_IMAGE_ASPECT_STENCIL_BIT));
    const char* vuid = other && (u->usage & ~img->usage)
                           ? (img->separateStencilUsage ? "VUID-VkImageViewCreateInfo-pNext-02664"
                                                        : "VUID-VkImageViewCreateInfo-pNext-02662")
                       : stencil && (u->usage & ~img->stencilUsage) ? "VUID-VkImageViewCreateInfo-pNext-02663"
                                                                    : nullptr;
    if (vuid) {
      report(img, Severity::Error, vuid,
             "vkCreateImageView: VkImageViewUsageCreateInfo::usage 0x%x is not within the image's usage 0x%x "
             "(stencilUsage 0x%x, aspects 0x%x)",
             u->usage, img->usage, img->stencilUsage, aspects);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  auto* view = createObject<ImageView>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, img);
  if (!view) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pView = toHandle(view);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyImageView(VkDevice device, VkImageView view,
                                                 const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<ImageView>(device, view, pAllocator, "vkDestroyImageView",
                                        "VUID-vkDestroyImageView-imageView-parameter",
                                        "VUID-vkDestroyImageView-imageView-01026");
}

}  // extern "C"
