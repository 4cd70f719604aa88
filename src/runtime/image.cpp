#include "runtime/image.hpp"

#include <algorithm>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/memory.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "runtime/swapchain.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

const VkImageStencilUsageCreateInfo* stencilUsageInfo(const VkImageCreateInfo& info) {
  if (!(formatAspects(info.format) & VK_IMAGE_ASPECT_STENCIL_BIT)) return nullptr;  // applies to stencil formats only
  return findInChain<VkImageStencilUsageCreateInfo>(info.pNext, VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO);
}

}  // namespace

VkExtent3D mipExtent(VkExtent3D e, uint32_t mip) {
  return {std::max(1u, e.width >> mip), std::max(1u, e.height >> mip), std::max(1u, e.depth >> mip)};
}

Image::Image(Device* dev, const VkImageCreateInfo& info, const FormatInfo* f)
    : Object(kType, dev->instance, dev),
      type(info.imageType),
      format(info.format),
      formatInfo(f),
      extent(info.extent),
      mipLevels(info.mipLevels),
      arrayLayers(info.arrayLayers),
      usage(info.usage),
      stencilUsage(stencilUsageInfo(info) ? stencilUsageInfo(info)->stencilUsage : info.usage),
      separateStencilUsage(stencilUsageInfo(info) != nullptr),
      tiling(info.tiling),
      flags(info.flags),
      samples(uint32_t(info.samples)),
      pixelSize(f->texelSize * uint32_t(info.samples)),
      aspects(formatAspects(info.format)) {
  if (auto* list =
          findInChain<VkImageFormatListCreateInfo>(info.pNext, VK_STRUCTURE_TYPE_IMAGE_FORMAT_LIST_CREATE_INFO))
    viewFormats.assign(list->pViewFormats, list->pViewFormats + list->viewFormatCount);
  VkDeviceSize offset = 0;
  for (uint32_t m = 0; m < mipLevels; ++m) {
    MipLayout l;
    l.extent = mipExtent(extent, m);
    l.offset = offset;
    const uint32_t b = f->block;  // 4 for the BC formats: rows of blocks
    l.rowPitch = VkDeviceSize((l.extent.width + b - 1) / b) * pixelSize;
    l.depthPitch = l.rowPitch * ((l.extent.height + b - 1) / b);
    l.arrayPitch = l.depthPitch * l.extent.depth;
    offset += l.arrayPitch * arrayLayers;
    mips.push_back(l);
  }
  size = offset;
}

uint8_t* Image::data() const { return memory ? memory->base + memoryOffset : nullptr; }

}  // namespace vkrt

using namespace vkrt;

namespace {

uint32_t maxMipLevels(VkExtent3D e) {
  uint32_t m = std::max({e.width, e.height, e.depth});
  uint32_t levels = 1;
  while (m > 1) {
    m >>= 1;
    ++levels;
  }
  return levels;
}

// Checks a VkImageCreateInfo; reports and returns the error code, or VK_SUCCESS.
VkResult checkImageInfo(Device* dev, const VkImageCreateInfo& ci, const FormatInfo** formatOut) {
  const VkPhysicalDeviceLimits& l = dev->physicalDevice->properties10.limits;
  // VUID-VkImageCreateInfo-extent-00944/00945/00946
  if (ci.extent.width == 0 || ci.extent.height == 0 || ci.extent.depth == 0) {
    report(dev, Severity::Error,
           ci.extent.width == 0    ? "VUID-VkImageCreateInfo-extent-00944"
           : ci.extent.height == 0 ? "VUID-VkImageCreateInfo-extent-00945"
                                   : "VUID-VkImageCreateInfo-extent-00946",
           "vkCreateImage: extent (%u, %u, %u) has a zero dimension", ci.extent.width, ci.extent.height,
           ci.extent.depth);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-mipLevels-00947 / arrayLayers-00948
  if (ci.mipLevels == 0 || ci.arrayLayers == 0) {
    report(dev, Severity::Error,
           ci.mipLevels == 0 ? "VUID-VkImageCreateInfo-mipLevels-00947" : "VUID-VkImageCreateInfo-arrayLayers-00948",
           "vkCreateImage: mipLevels %u and arrayLayers %u must be at least 1", ci.mipLevels, ci.arrayLayers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-imageType-00956 / 00957: 1D images have height and depth 1, 2D depth 1
  if ((ci.imageType == VK_IMAGE_TYPE_1D && (ci.extent.height != 1 || ci.extent.depth != 1)) ||
      (ci.imageType == VK_IMAGE_TYPE_2D && ci.extent.depth != 1)) {
    report(dev, Severity::Error,
           ci.imageType == VK_IMAGE_TYPE_1D ? "VUID-VkImageCreateInfo-imageType-00956"
                                            : "VUID-VkImageCreateInfo-imageType-00957",
           "vkCreateImage: extent (%u, %u, %u) does not fit image type %d", ci.extent.width, ci.extent.height,
           ci.extent.depth, (int)ci.imageType);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-imageType-00961: 3D images have one layer
  if (ci.imageType == VK_IMAGE_TYPE_3D && ci.arrayLayers != 1) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-imageType-00961",
           "vkCreateImage: a 3D image has arrayLayers %u, not 1", ci.arrayLayers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-imageType-00954: cube-compatible images are square 2D images with >= 6 layers
  if ((ci.flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT) &&
      (ci.imageType != VK_IMAGE_TYPE_2D || ci.extent.width != ci.extent.height || ci.arrayLayers < 6)) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-imageType-00954",
           "vkCreateImage: a cube-compatible image of type %d has extent %ux%u and %u layers (square 2D, >= 6 needed)",
           (int)ci.imageType, ci.extent.width, ci.extent.height, ci.arrayLayers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-flags-01572 / 01573: BLOCK_TEXEL_VIEW_COMPATIBLE is for compressed formats, with
  // MUTABLE_FORMAT
  if ((ci.flags & VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT) &&
      (!isCompressedFormat(ci.format) || !(ci.flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT))) {
    const bool compressed = isCompressedFormat(ci.format);
    report(dev, Severity::Error,
           compressed ? "VUID-VkImageCreateInfo-flags-01573" : "VUID-VkImageCreateInfo-flags-01572",
           "vkCreateImage: flags 0x%x have VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT %s (format %d)", ci.flags,
           compressed ? "without VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT" : "with an uncompressed format", (int)ci.format);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-mipLevels-00958
  if (ci.mipLevels > maxMipLevels(ci.extent)) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-mipLevels-00958",
           "vkCreateImage: mipLevels %u exceeds %u, the full chain for extent (%u, %u, %u)", ci.mipLevels,
           maxMipLevels(ci.extent), ci.extent.width, ci.extent.height, ci.extent.depth);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkImageCreateInfo-samples-02257: multisampled images are 2D, optimal, one level, not cube-compatible
  if (ci.samples != VK_SAMPLE_COUNT_1_BIT &&
      (ci.imageType != VK_IMAGE_TYPE_2D || ci.tiling != VK_IMAGE_TILING_OPTIMAL || ci.mipLevels != 1 ||
       (ci.flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT))) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-samples-02257",
           "vkCreateImage: samples %u with image type %d, tiling %d, %u mip levels, flags 0x%x (a multisampled image "
           "is 2D, optimal, one level, not cube-compatible)",
           (unsigned)ci.samples, (int)ci.imageType, (int)ci.tiling, ci.mipLevels, ci.flags);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  uint32_t maxDim = ci.imageType == VK_IMAGE_TYPE_1D   ? l.maxImageDimension1D
                    : ci.imageType == VK_IMAGE_TYPE_2D ? l.maxImageDimension2D
                                                       : l.maxImageDimension3D;
  // VUID-VkImageCreateInfo-extent-02252/02253/02254, arrayLayers-02256
  if (std::max({ci.extent.width, ci.extent.height, ci.extent.depth}) > maxDim ||
      ci.arrayLayers > l.maxImageArrayLayers) {
    report(dev, Severity::Error,
           ci.arrayLayers > l.maxImageArrayLayers ? "VUID-VkImageCreateInfo-arrayLayers-02256"
                                                  : "VUID-VkImageCreateInfo-extent-02252",
           "vkCreateImage: extent (%u, %u, %u) x %u layers exceeds the limits (%u, %u layers)", ci.extent.width,
           ci.extent.height, ci.extent.depth, ci.arrayLayers, maxDim, l.maxImageArrayLayers);
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  // VkImageStencilUsageCreateInfo: the attachment bits agree with usage (VUID-VkImageCreateInfo-format-02795 /
  // 02796 / 02797 / 02798), a transient stencil is an attachment only (VUID-VkImageStencilUsageCreateInfo-
  // stencilUsage-02539).
  VkImageUsageFlags stencilUsage = ci.usage;
  if (const VkImageStencilUsageCreateInfo* su = stencilUsageInfo(ci)) {
    stencilUsage = su->stencilUsage;
    const VkImageUsageFlags ds = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    const VkImageUsageFlags transient = VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT;
    const char* vuid =
        (ci.usage & ds) && !(stencilUsage & ds)                 ? "VUID-VkImageCreateInfo-format-02795"
        : !(ci.usage & ds) && (stencilUsage & ds)               ? "VUID-VkImageCreateInfo-format-02796"
        : (ci.usage & transient) && !(stencilUsage & transient) ? "VUID-VkImageCreateInfo-format-02797"
        : !(ci.usage & transient) && (stencilUsage & transient) ? "VUID-VkImageCreateInfo-format-02798"
        : (stencilUsage & transient) && (stencilUsage & ~(transient | ds | VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT))
            ? "VUID-VkImageStencilUsageCreateInfo-stencilUsage-02539"
            : nullptr;
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "vkCreateImage: usage 0x%x and VkImageStencilUsageCreateInfo::stencilUsage 0x%x", ci.usage, stencilUsage);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // Both aspects' usages must be supported (vkGetPhysicalDeviceImageFormatProperties2 answers for the pair).
  VkImageFormatProperties props;
  VkResult r = vkrt_GetPhysicalDeviceImageFormatProperties(toHandle(dev->physicalDevice), ci.format, ci.imageType,
                                                           ci.tiling, ci.usage | stencilUsage, ci.flags, &props);
  // VUID-VkImageCreateInfo-imageCreateMaxMipLevels-02251: format/type/tiling/usage/flags must be supported
  if (r != VK_SUCCESS) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-imageCreateMaxMipLevels-02251",
           "vkCreateImage: format %d with usage 0x%x (stencil 0x%x), flags 0x%x, type %d is not supported by vkrt",
           (int)ci.format, ci.usage, stencilUsage, ci.flags, (int)ci.imageType);
    return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  // VUID-VkImageCreateInfo-samples-02258: a sample count the format supports
  if (!(props.sampleCounts & ci.samples)) {
    report(dev, Severity::Error, "VUID-VkImageCreateInfo-samples-02258",
           "vkCreateImage: samples %u is not among the sample counts 0x%x of format %d with usage 0x%x",
           (unsigned)ci.samples, props.sampleCounts, (int)ci.format, ci.usage);
    return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  // VK_KHR_image_format_list: the formats the views will have.
  if (auto* list =
          findInChain<VkImageFormatListCreateInfo>(ci.pNext, VK_STRUCTURE_TYPE_IMAGE_FORMAT_LIST_CREATE_INFO)) {
    // VUID-VkImageCreateInfo-flags-04738: without MUTABLE_FORMAT, at most the image's own format
    if (!(ci.flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT) && list->viewFormatCount > 1) {
      report(dev, Severity::Error, "VUID-VkImageCreateInfo-flags-04738",
             "vkCreateImage: VkImageFormatListCreateInfo::viewFormatCount is %u, but flags 0x%x has no "
             "VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT (0 or 1 format allowed)",
             list->viewFormatCount, ci.flags);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkImageCreateInfo-pNext-06722: each format compatible with the image's (viewFormatCompatible: the same
    // class, or with BLOCK_TEXEL_VIEW_COMPATIBLE an uncompressed format of the block's size); a format vkrt does not
    // know may belong to the class: not reported.
    const FormatInfo* own = formatInfo(ci.format);
    for (uint32_t i = 0; i < list->viewFormatCount && own; ++i) {
      const FormatInfo* f = formatInfo(list->pViewFormats[i]);
      if (f && !viewFormatCompatible(ci.format, list->pViewFormats[i], ci.flags)) {
        report(dev, Severity::Error, "VUID-VkImageCreateInfo-pNext-06722",
               "vkCreateImage: VkImageFormatListCreateInfo::pViewFormats[%u] (format %d, %u bytes a texel) is not "
               "compatible with the image's format %d (%u bytes, flags 0x%x)",
               i, (int)list->pViewFormats[i], f->texelSize, (int)ci.format, own->texelSize, ci.flags);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
  }
  *formatOut = formatInfo(ci.format);
  return VK_SUCCESS;
}

void requirementsOf(const Image& img, VkMemoryRequirements* req) {
  req->size = std::max<VkDeviceSize>(Image::kAlignment,
                                     (img.size + Image::kAlignment - 1) / Image::kAlignment * Image::kAlignment);
  req->alignment = Image::kAlignment;
  req->memoryTypeBits = 1;
}

VkResult bindImage(Device* dev, const VkBindImageMemoryInfo& info, uint32_t index, bool bind2) {
  Image* img = fromHandle<Image>(info.image);
  Memory* mem = fromHandle<Memory>(info.memory);
  VkDeviceSize memoryOffset = info.memoryOffset;
  // VkBindImageMemorySwapchainInfoKHR: the image aliases a swapchain image (its memory at its offset).
  if (auto* sw = findInChain<VkBindImageMemorySwapchainInfoKHR>(
          info.pNext, VK_STRUCTURE_TYPE_BIND_IMAGE_MEMORY_SWAPCHAIN_INFO_KHR)) {
    Swapchain* sc = fromHandle<Swapchain>(sw->swapchain);
    // VUID-VkBindImageMemorySwapchainInfoKHR-swapchain-parameter,
    // VUID-VkBindImageMemorySwapchainInfoKHR-imageIndex-01644 VUID-VkBindImageMemoryInfo-pNext-01631
    const char* vuid = !sc ? "VUID-VkBindImageMemorySwapchainInfoKHR-swapchain-parameter"
                       : sw->imageIndex >= sc->images.size() ? "VUID-VkBindImageMemorySwapchainInfoKHR-imageIndex-01644"
                       : info.memory != VK_NULL_HANDLE       ? "VUID-VkBindImageMemoryInfo-pNext-01631"
                                                             : nullptr;
    if (vuid) {
      report(dev, Severity::Error, vuid,
             "vkBindImageMemory2: bind %u: VkBindImageMemorySwapchainInfoKHR names swapchain 0x%llx (%s) and image "
             "index %u, with memory 0x%llx (must be VK_NULL_HANDLE)",
             index, (unsigned long long)rawHandle(sw->swapchain), sc ? "live" : "not a live VkSwapchainKHR",
             sw->imageIndex, (unsigned long long)rawHandle(info.memory));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    const Image* target = fromHandle<Image>(sc->images[sw->imageIndex]);
    mem = target->memory;
    memoryOffset = target->memoryOffset;
  }
  if (!img || !mem) {
    report(dev, Severity::Error, "VUID-VkBindImageMemoryInfo-image-parameter",
           "vkBindImageMemory: bind %u names an image 0x%llx or memory 0x%llx that is not live", index,
           (unsigned long long)rawHandle(info.image), (unsigned long long)rawHandle(info.memory));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkBindImageMemoryInfo-image-07460
  if (img->memory) {
    report(img, Severity::Error, "VUID-VkBindImageMemoryInfo-image-07460", "vkBindImageMemory: already bound");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  VkMemoryRequirements req;
  requirementsOf(*img, &req);
  // VUID-VkBindImageMemoryInfo-memoryOffset-01613: aligned; -01046: inside the memory;
  // VUID-vkBindImageMemory-size-01049 / VUID-VkBindImageMemoryInfo-pNext-01617: the image fits
  const char* vuid = memoryOffset % req.alignment ? "VUID-VkBindImageMemoryInfo-memoryOffset-01613"
                     : memoryOffset >= mem->size  ? "VUID-VkBindImageMemoryInfo-memoryOffset-01046"
                     : req.size > mem->size - memoryOffset
                         ? (bind2 ? "VUID-VkBindImageMemoryInfo-pNext-01617" : "VUID-vkBindImageMemory-size-01049")
                         : nullptr;
  if (vuid) {
    report(img, Severity::Error, vuid,
           "%s: %llu bytes at memoryOffset %llu do not fit the %llu-byte memory (alignment %llu)",
           bind2 ? "vkBindImageMemory2" : "vkBindImageMemory", (unsigned long long)req.size,
           (unsigned long long)memoryOffset, (unsigned long long)mem->size, (unsigned long long)req.alignment);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  img->memory = mem;
  img->memoryOffset = memoryOffset;
  return VK_SUCCESS;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateImage(VkDevice device, const VkImageCreateInfo* pCreateInfo,
                                                const VkAllocationCallbacks* pAllocator, VkImage* pImage) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const FormatInfo* f = nullptr;
  VkResult r = checkImageInfo(dev, *pCreateInfo, &f);
  if (r != VK_SUCCESS) return r;
  Image* img = createObject<Image>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, f);
  if (!img) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pImage = toHandle(img);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyImage(VkDevice device, VkImage image, const VkAllocationCallbacks* pAllocator) {
  // VUID-vkDestroyImage-image-04882: a swapchain's images go with the swapchain.
  if (Image* img = fromHandle<Image>(image); img && img->presentable) {
    report(img, Severity::Error, "VUID-vkDestroyImage-image-04882",
           "vkDestroyImage: the image belongs to a swapchain (vkGetSwapchainImagesKHR); vkDestroySwapchainKHR "
           "destroys it");
    return;
  }
  destroyDeviceChildWhenIdle<Image>(device, image, pAllocator, "vkDestroyImage", "VUID-vkDestroyImage-image-parameter",
                                    "VUID-vkDestroyImage-image-01000");
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetImageMemoryRequirements(VkDevice, VkImage image, VkMemoryRequirements* pReq) {
  requirementsOf(*fromHandleUnchecked<Image>(image), pReq);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetImageMemoryRequirements2(VkDevice, const VkImageMemoryRequirementsInfo2* pInfo,
                                                            VkMemoryRequirements2* pReq) {
  requirementsOf(*fromHandleUnchecked<Image>(pInfo->image), &pReq->memoryRequirements);
  for (auto* s = static_cast<VkBaseOutStructure*>(pReq->pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS) {
      auto* d = reinterpret_cast<VkMemoryDedicatedRequirements*>(s);
      d->prefersDedicatedAllocation = VK_FALSE;
      d->requiresDedicatedAllocation = VK_FALSE;
    }
  }
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceImageMemoryRequirements(VkDevice device,
                                                                 const VkDeviceImageMemoryRequirements* pInfo,
                                                                 VkMemoryRequirements2* pReq) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const FormatInfo* f = formatInfo(pInfo->pCreateInfo->format);
  if (!f || pInfo->pCreateInfo->mipLevels == 0) {
    pReq->memoryRequirements = {0, Image::kAlignment, 0};
    return;
  }
  Image probe(dev, *pInfo->pCreateInfo, f);  // computes the layout; never handed out
  requirementsOf(probe, &pReq->memoryRequirements);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetImageSparseMemoryRequirements(VkDevice, VkImage, uint32_t* pCount,
                                                                 VkSparseImageMemoryRequirements*) {
  *pCount = 0;  // no sparse images
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetImageSparseMemoryRequirements2(VkDevice, const VkImageSparseMemoryRequirementsInfo2*,
                                                                  uint32_t* pCount, VkSparseImageMemoryRequirements2*) {
  *pCount = 0;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetDeviceImageSparseMemoryRequirements(VkDevice, const VkDeviceImageMemoryRequirements*,
                                                                       uint32_t* pCount,
                                                                       VkSparseImageMemoryRequirements2*) {
  *pCount = 0;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BindImageMemory(VkDevice device, VkImage image, VkDeviceMemory memory,
                                                    VkDeviceSize memoryOffset) {
  VkBindImageMemoryInfo info{VK_STRUCTURE_TYPE_BIND_IMAGE_MEMORY_INFO, nullptr, image, memory, memoryOffset};
  return bindImage(fromHandleUnchecked<Device>(device), info, 0, false);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_BindImageMemory2(VkDevice device, uint32_t count,
                                                     const VkBindImageMemoryInfo* pInfos) {
  Device* dev = fromHandleUnchecked<Device>(device);
  for (uint32_t i = 0; i < count; ++i) {
    VkResult r = bindImage(dev, pInfos[i], i, true);
    if (r != VK_SUCCESS) return r;
  }
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetImageSubresourceLayout(VkDevice device, VkImage image,
                                                          const VkImageSubresource* pSubresource,
                                                          VkSubresourceLayout* pLayout) {
  Image* img = fromHandle<Image>(image);
  *pLayout = {};
  if (!img || pSubresource->mipLevel >= img->mipLevels || pSubresource->arrayLayer >= img->arrayLayers) {
    // VUID-vkGetImageSubresourceLayout-mipLevel-01716 / arrayLayer-01717
    report(img ? static_cast<Object*>(img) : fromHandle<Device>(device), Severity::Error,
           img && pSubresource->mipLevel < img->mipLevels ? "VUID-vkGetImageSubresourceLayout-arrayLayer-01717"
                                                          : "VUID-vkGetImageSubresourceLayout-mipLevel-01716",
           "vkGetImageSubresourceLayout: subresource (mip %u, layer %u) is outside the image", pSubresource->mipLevel,
           pSubresource->arrayLayer);
    return;
  }
  // VUID-vkGetImageSubresourceLayout-aspectMask-00997: one aspect the format has (VUID-...-format-04462/04463/04464)
  const VkImageAspectFlags a = pSubresource->aspectMask;
  if ((a & (a - 1)) || !(a & img->aspects)) {
    report(img, Severity::Error,
           img->aspects == VK_IMAGE_ASPECT_COLOR_BIT    ? "VUID-vkGetImageSubresourceLayout-format-04461"
           : (a & (a - 1))                              ? "VUID-vkGetImageSubresourceLayout-aspectMask-00997"
           : (img->aspects & VK_IMAGE_ASPECT_DEPTH_BIT) ? "VUID-vkGetImageSubresourceLayout-format-04462"
                                                        : "VUID-vkGetImageSubresourceLayout-format-04463",
           "vkGetImageSubresourceLayout: aspectMask 0x%x is not one aspect of the image's (0x%x)", a, img->aspects);
    return;
  }
  // Every aspect lies in the same texels (image.hpp): a depth/stencil aspect reports the combined texels' layout.
  const MipLayout& m = img->mips[pSubresource->mipLevel];
  pLayout->offset = m.offset + pSubresource->arrayLayer * m.arrayPitch;
  pLayout->size = m.arrayPitch;
  pLayout->rowPitch = m.rowPitch;
  pLayout->depthPitch = m.depthPitch;
  pLayout->arrayPitch = m.arrayPitch;
}

}  // extern "C"
