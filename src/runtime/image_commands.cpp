// Image transfer commands: vkCmdCopyBufferToImage(2), vkCmdCopyImageToBuffer(2), vkCmdCopyImage(2),
// vkCmdClearColorImage (vkCmdBlitImage is not implemented: no format claims BLIT_SRC/BLIT_DST). Each validates its
// regions (reporting the VUID and recording nothing when one is invalid) and records a closure that runs the routines
// of runtime/image_copy.hpp.
#include <vector>

#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/image.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/memory.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;

namespace {

using ull = unsigned long long;

// The VUIDs one command reports (they differ between the 1 and 2 versions of each command).
struct Vuids {
  const char* fn;
  const char* usage;   // image transfer usage
  const char* bound;   // image bound to memory
  const char* layout;  // image layout
  const char* mip;     // subresource mip level
  const char* layers;  // subresource layers
  const char* bounds;  // region inside the (mip of the) image
  const char* aspect;  // color aspect only
  // Buffer <-> image only:
  const char* bufUsage;
  const char* bufBound;
  const char* bufOffset;    // multiple of the texel size
  const char* bufSize;      // buffer large enough
  const char* rowLength;    // bufferRowLength >= width
  const char* imageHeight;  // bufferImageHeight >= height
};

constexpr Vuids kBufferToImage{"vkCmdCopyBufferToImage",
                               "VUID-vkCmdCopyBufferToImage-dstImage-00177",
                               "VUID-vkCmdCopyBufferToImage-dstImage-00178",
                               "VUID-vkCmdCopyBufferToImage-dstImageLayout-01396",
                               "VUID-vkCmdCopyBufferToImage-imageSubresource-01701",
                               "VUID-vkCmdCopyBufferToImage-imageSubresource-01702",
                               "VUID-vkCmdCopyBufferToImage-pRegions-06217",
                               "VUID-vkCmdCopyBufferToImage-aspectMask-00211",
                               "VUID-vkCmdCopyBufferToImage-srcBuffer-00174",
                               "VUID-vkCmdCopyBufferToImage-srcBuffer-00176",
                               "VUID-vkCmdCopyBufferToImage-bufferOffset-00193",
                               "VUID-vkCmdCopyBufferToImage-pRegions-00171",
                               "VUID-VkBufferImageCopy-bufferRowLength-00195",
                               "VUID-VkBufferImageCopy-bufferImageHeight-00196"};
constexpr Vuids kBufferToImage2{"vkCmdCopyBufferToImage2",
                                "VUID-VkCopyBufferToImageInfo2-dstImage-00177",
                                "VUID-VkCopyBufferToImageInfo2-dstImage-00178",
                                "VUID-VkCopyBufferToImageInfo2-dstImageLayout-01396",
                                "VUID-VkCopyBufferToImageInfo2-imageSubresource-01701",
                                "VUID-VkCopyBufferToImageInfo2-imageSubresource-01702",
                                "VUID-VkCopyBufferToImageInfo2-pRegions-00172",
                                "VUID-VkCopyBufferToImageInfo2-aspectMask-00211",
                                "VUID-VkCopyBufferToImageInfo2-srcBuffer-00174",
                                "VUID-VkCopyBufferToImageInfo2-srcBuffer-00176",
                                "VUID-VkCopyBufferToImageInfo2-bufferOffset-00193",
                                "VUID-VkCopyBufferToImageInfo2-pRegions-00171",
                                "VUID-VkBufferImageCopy2-bufferRowLength-00195",
                                "VUID-VkBufferImageCopy2-bufferImageHeight-00196"};
constexpr Vuids kImageToBuffer{"vkCmdCopyImageToBuffer",
                               "VUID-vkCmdCopyImageToBuffer-srcImage-00186",
                               "VUID-vkCmdCopyImageToBuffer-srcImage-00187",
                               "VUID-vkCmdCopyImageToBuffer-srcImageLayout-01397",
                               "VUID-vkCmdCopyImageToBuffer-imageSubresource-01703",
                               "VUID-vkCmdCopyImageToBuffer-imageSubresource-01704",
                               "VUID-vkCmdCopyImageToBuffer-pRegions-06220",
                               "VUID-vkCmdCopyImageToBuffer-aspectMask-00211",
                               "VUID-vkCmdCopyImageToBuffer-dstBuffer-00191",
                               "VUID-vkCmdCopyImageToBuffer-dstBuffer-00192",
                               "VUID-vkCmdCopyImageToBuffer-bufferOffset-00193",
                               "VUID-vkCmdCopyImageToBuffer-pRegions-00183",
                               "VUID-VkBufferImageCopy-bufferRowLength-00195",
                               "VUID-VkBufferImageCopy-bufferImageHeight-00196"};
constexpr Vuids kImageToBuffer2{"vkCmdCopyImageToBuffer2",
                                "VUID-VkCopyImageToBufferInfo2-srcImage-00186",
                                "VUID-VkCopyImageToBufferInfo2-srcImage-00187",
                                "VUID-VkCopyImageToBufferInfo2-srcImageLayout-01397",
                                "VUID-VkCopyImageToBufferInfo2-imageSubresource-01703",
                                "VUID-VkCopyImageToBufferInfo2-imageSubresource-01704",
                                "VUID-VkCopyImageToBufferInfo2-pRegions-00182",
                                "VUID-VkCopyImageToBufferInfo2-aspectMask-00211",
                                "VUID-VkCopyImageToBufferInfo2-dstBuffer-00191",
                                "VUID-VkCopyImageToBufferInfo2-dstBuffer-00192",
                                "VUID-VkCopyImageToBufferInfo2-bufferOffset-00193",
                                "VUID-VkCopyImageToBufferInfo2-pRegions-00183",
                                "VUID-VkBufferImageCopy2-bufferRowLength-00195",
                                "VUID-VkBufferImageCopy2-bufferImageHeight-00196"};
// vkCmdCopyImage(2): one table for the source and one for the destination image.
constexpr Vuids kCopySrc{"vkCmdCopyImage",
                         "VUID-vkCmdCopyImage-srcImage-00126",
                         "VUID-vkCmdCopyImage-srcImage-00127",
                         "VUID-vkCmdCopyImage-srcImageLayout-01917",
                         "VUID-vkCmdCopyImage-srcSubresource-01696",
                         "VUID-vkCmdCopyImage-srcSubresource-01698",
                         "VUID-vkCmdCopyImage-srcOffset-00144",
                         "VUID-vkCmdCopyImage-aspectMask-00142"};
constexpr Vuids kCopyDst{"vkCmdCopyImage",
                         "VUID-vkCmdCopyImage-dstImage-00131",
                         "VUID-vkCmdCopyImage-dstImage-00132",
                         "VUID-vkCmdCopyImage-dstImageLayout-01395",
                         "VUID-vkCmdCopyImage-dstSubresource-01697",
                         "VUID-vkCmdCopyImage-dstSubresource-01699",
                         "VUID-vkCmdCopyImage-dstOffset-00150",
                         "VUID-vkCmdCopyImage-aspectMask-00143"};
constexpr Vuids kCopySrc2{"vkCmdCopyImage2",
                          "VUID-VkCopyImageInfo2-srcImage-00126",
                          "VUID-VkCopyImageInfo2-srcImage-00127",
                          "VUID-VkCopyImageInfo2-srcImageLayout-01917",
                          "VUID-VkCopyImageInfo2-srcSubresource-01696",
                          "VUID-VkCopyImageInfo2-srcSubresource-01698",
                          "VUID-VkCopyImageInfo2-srcOffset-00144",
                          "VUID-VkCopyImageInfo2-aspectMask-00142"};
constexpr Vuids kCopyDst2{"vkCmdCopyImage2",
                          "VUID-VkCopyImageInfo2-dstImage-00131",
                          "VUID-VkCopyImageInfo2-dstImage-00132",
                          "VUID-VkCopyImageInfo2-dstImageLayout-01395",
                          "VUID-VkCopyImageInfo2-dstSubresource-01697",
                          "VUID-VkCopyImageInfo2-dstSubresource-01699",
                          "VUID-VkCopyImageInfo2-dstOffset-00150",
                          "VUID-VkCopyImageInfo2-aspectMask-00143"};
constexpr Vuids kClear{"vkCmdClearColorImage",
                       "VUID-vkCmdClearColorImage-image-00002",
                       "VUID-vkCmdClearColorImage-image-00003",
                       "VUID-vkCmdClearColorImage-imageLayout-01394",
                       "VUID-vkCmdClearColorImage-baseMipLevel-01470",
                       "VUID-vkCmdClearColorImage-baseArrayLayer-01472",
                       "VUID-vkCmdClearColorImage-pRanges-01692",
                       "VUID-vkCmdClearColorImage-aspectMask-02498"};

bool layoutOk(VkImageLayout l, bool dst) {
  return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHARED_PRESENT_KHR ||
         l == (dst ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

// A live image bound to memory, with the transfer usage and a transfer layout; reports otherwise.
Image* transferImage(CommandBuffer* cb, VkImage h, bool dst, VkImageLayout layout, const Vuids& v) {
  Image* img = fromHandle<Image>(h);
  if (!img) {
    report(cb, Severity::Error, nullptr, "%s: %s 0x%llx is not a live VkImage", v.fn, dst ? "dstImage" : "srcImage",
           (ull)rawHandle(h));
    return nullptr;
  }
  // VUID ...-dstImage-00177 / srcImage-00186 / image-00002 etc.: transfer usage
  if (!(img->usage & (dst ? VK_IMAGE_USAGE_TRANSFER_DST_BIT : VK_IMAGE_USAGE_TRANSFER_SRC_BIT))) {
    report(img, Severity::Error, v.usage,
           "%s: the image was created without VK_IMAGE_USAGE_TRANSFER_%s_BIT (usage 0x%x)", v.fn, dst ? "DST" : "SRC",
           img->usage);
    return nullptr;
  }
  // VUID ...-00178 / 00187 / 00127 / 00132 / image-00003: bound to memory
  if (!img->memory) {
    report(img, Severity::Error, v.bound, "%s: the image is not bound to memory", v.fn);
    return nullptr;
  }
  // VUID ...-dstImageLayout-01396 / srcImageLayout-01397 / 01917 / 01395 / imageLayout-01394
  if (!layoutOk(layout, dst)) {
    report(img, Severity::Error, v.layout, "%s: image layout %d is not GENERAL, SHARED_PRESENT or TRANSFER_%s_OPTIMAL",
           v.fn, (int)layout, dst ? "DST" : "SRC");
    return nullptr;
  }
  return img;
}

// Checks that [offset, offset + extent) of (mip, layers) lies inside the image.
bool regionInImage(const Image& img, const VkImageSubresourceLayers& sub, VkOffset3D off, VkExtent3D ext,
                   uint32_t index, const char* what, const Vuids& v) {
  // VUID ...-aspectMask-00211 / 00142 / 00143: vkrt images have the color aspect only
  if (sub.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT) {
    report(&img, Severity::Error, v.aspect, "%s: pRegions[%u].%s aspectMask 0x%x is not VK_IMAGE_ASPECT_COLOR_BIT",
           v.fn, index, what, sub.aspectMask);
    return false;
  }
  // VUID ...-imageSubresource-01701/01703, srcSubresource-01696, dstSubresource-01697: mip level exists
  if (sub.mipLevel >= img.mipLevels) {
    report(&img, Severity::Error, v.mip, "%s: pRegions[%u].%s.mipLevel %u, the image has %u", v.fn, index, what,
           sub.mipLevel, img.mipLevels);
    return false;
  }
  // VUID ...-imageSubresource-01702/01704, srcSubresource-01698, dstSubresource-01699: layers exist
  if (sub.layerCount == 0 || sub.baseArrayLayer >= img.arrayLayers ||
      sub.layerCount > img.arrayLayers - sub.baseArrayLayer) {
    report(&img, Severity::Error, v.layers, "%s: pRegions[%u].%s layers [%u, +%u) exceed the image's %u layers", v.fn,
           index, what, sub.baseArrayLayer, sub.layerCount, img.arrayLayers);
    return false;
  }
  // VUID ...-pRegions-06217/06220/00172/00182, srcOffset-00144, dstOffset-00150: the region fits the mip
  VkExtent3D m = img.mips[sub.mipLevel].extent;
  auto fits = [](int32_t o, uint32_t e, uint32_t size) { return o >= 0 && e > 0 && uint64_t(o) + e <= size; };
  if (!fits(off.x, ext.width, m.width) || !fits(off.y, ext.height, m.height) || !fits(off.z, ext.depth, m.depth)) {
    report(&img, Severity::Error, v.bounds,
           "%s: pRegions[%u] offset (%d, %d, %d) extent (%u, %u, %u) exceeds mip %u's extent (%u, %u, %u)", v.fn, index,
           off.x, off.y, off.z, ext.width, ext.height, ext.depth, sub.mipLevel, m.width, m.height, m.depth);
    return false;
  }
  return true;
}

void recordBufferImage(CommandBuffer* cb, VkBuffer bufferH, VkImage imageH, VkImageLayout layout,
                       std::vector<VkBufferImageCopy2> regions, bool toImage, const Vuids& v) {
  Buffer* buf = fromHandle<Buffer>(bufferH);
  if (!buf) {
    report(cb, Severity::Error, nullptr, "%s: buffer 0x%llx is not a live VkBuffer", v.fn, (ull)rawHandle(bufferH));
    return;
  }
  // VUID ...-srcBuffer-00174 / dstBuffer-00191
  VkBufferUsageFlags need = toImage ? VK_BUFFER_USAGE_TRANSFER_SRC_BIT : VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (!(buf->usage & need)) {
    report(buf, Severity::Error, v.bufUsage, "%s: the buffer lacks VK_BUFFER_USAGE_TRANSFER_%s_BIT (usage 0x%x)", v.fn,
           toImage ? "SRC" : "DST", buf->usage);
    return;
  }
  // VUID ...-srcBuffer-00176 / dstBuffer-00192
  if (!buf->memory) {
    report(buf, Severity::Error, v.bufBound, "%s: the buffer is not bound to memory", v.fn);
    return;
  }
  Image* img = transferImage(cb, imageH, toImage, layout, v);
  if (!img) return;
  const uint32_t t = img->formatInfo->texelSize;
  for (uint32_t i = 0; i < regions.size(); ++i) {
    const VkBufferImageCopy2& r = regions[i];
    if (!regionInImage(*img, r.imageSubresource, r.imageOffset, r.imageExtent, i, "imageSubresource", v)) return;
    // VUID-VkBufferImageCopy(2)-bufferRowLength-00195 / bufferImageHeight-00196
    if ((r.bufferRowLength && r.bufferRowLength < r.imageExtent.width) ||
        (r.bufferImageHeight && r.bufferImageHeight < r.imageExtent.height)) {
      bool row = r.bufferRowLength && r.bufferRowLength < r.imageExtent.width;
      report(buf, Severity::Error, row ? v.rowLength : v.imageHeight,
             "%s: pRegions[%u] bufferRowLength %u / bufferImageHeight %u is smaller than the extent (%u, %u)", v.fn, i,
             r.bufferRowLength, r.bufferImageHeight, r.imageExtent.width, r.imageExtent.height);
      return;
    }
    // VUID ...-bufferOffset-00193: a multiple of the texel size
    if (r.bufferOffset % t) {
      report(buf, Severity::Error, v.bufOffset,
             "%s: pRegions[%u].bufferOffset %llu is not a multiple of the %u-byte texel", v.fn, i, (ull)r.bufferOffset,
             t);
      return;
    }
    // VUID ...-pRegions-00171 / 00183: the buffer holds every addressed texel
    VkDeviceSize need = bufferFootprint(r, t);
    if (r.bufferOffset > buf->size || need > buf->size - r.bufferOffset) {
      report(buf, Severity::Error, v.bufSize,
             "%s: pRegions[%u] needs %llu bytes at bufferOffset %llu; the buffer has %llu", v.fn, i, (ull)need,
             (ull)r.bufferOffset, (ull)buf->size);
      return;
    }
  }
  cb->record([buf, img, regions = std::move(regions), toImage](ExecState&) {
    for (const VkBufferImageCopy2& r : regions) copyBufferImage(*img, buf->data(), r, toImage);
  });
}

VkBufferImageCopy2 toCopy2(const VkBufferImageCopy& r) {
  return {VK_STRUCTURE_TYPE_BUFFER_IMAGE_COPY_2,
          nullptr,
          r.bufferOffset,
          r.bufferRowLength,
          r.bufferImageHeight,
          r.imageSubresource,
          r.imageOffset,
          r.imageExtent};
}

void recordImageCopy(CommandBuffer* cb, VkImage srcH, VkImageLayout srcLayout, VkImage dstH, VkImageLayout dstLayout,
                     std::vector<VkImageCopy2> regions, const Vuids& vs, const Vuids& vd, const char* sizeVuid,
                     const char* layerVuid) {
  Image* src = transferImage(cb, srcH, false, srcLayout, vs);
  Image* dst = src ? transferImage(cb, dstH, true, dstLayout, vd) : nullptr;
  if (!src || !dst) return;
  // VUID-vkCmdCopyImage-srcImage-01548: size-compatible formats (same texel size for vkrt's formats)
  if (src->formatInfo->texelSize != dst->formatInfo->texelSize) {
    report(dst, Severity::Error, sizeVuid, "%s: formats %d and %d have different texel sizes (%u, %u)", vs.fn,
           (int)src->format, (int)dst->format, src->formatInfo->texelSize, dst->formatInfo->texelSize);
    return;
  }
  for (uint32_t i = 0; i < regions.size(); ++i) {
    VkImageCopy2& r = regions[i];
    // A 3D image's slices correspond to the layers of a 2D image: the 3D side has one layer and a depth.
    if (src->type == VK_IMAGE_TYPE_3D && dst->type != VK_IMAGE_TYPE_3D &&
        r.extent.depth != r.dstSubresource.layerCount) {
      report(dst, Severity::Error, layerVuid, "%s: pRegions[%u] copies %u slices into %u layers", vs.fn, i,
             r.extent.depth, r.dstSubresource.layerCount);
      return;
    }
    if (src->type != VK_IMAGE_TYPE_3D && dst->type == VK_IMAGE_TYPE_3D &&
        r.extent.depth != r.srcSubresource.layerCount) {
      report(dst, Severity::Error, layerVuid, "%s: pRegions[%u] copies %u layers into %u slices", vs.fn, i,
             r.srcSubresource.layerCount, r.extent.depth);
      return;
    }
    // VUID-vkCmdCopyImage-srcImage-07744: with the same image type, the layer counts match
    if (src->type == dst->type && r.srcSubresource.layerCount != r.dstSubresource.layerCount) {
      report(dst, Severity::Error, layerVuid, "%s: pRegions[%u] copies %u layers into %u", vs.fn, i,
             r.srcSubresource.layerCount, r.dstSubresource.layerCount);
      return;
    }
    VkExtent3D srcExt = r.extent, dstExt = r.extent;
    if (src->type != VK_IMAGE_TYPE_3D && dst->type == VK_IMAGE_TYPE_3D) srcExt.depth = 1;
    if (src->type == VK_IMAGE_TYPE_3D && dst->type != VK_IMAGE_TYPE_3D) dstExt.depth = 1;
    if (!regionInImage(*src, r.srcSubresource, r.srcOffset, srcExt, i, "srcSubresource", vs) ||
        !regionInImage(*dst, r.dstSubresource, r.dstOffset, dstExt, i, "dstSubresource", vd))
      return;
  }
  cb->record([src, dst, regions = std::move(regions)](ExecState&) {
    for (const VkImageCopy2& r : regions) copyImageImage(*src, *dst, r);
  });
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBufferToImage(VkCommandBuffer commandBuffer, VkBuffer srcBuffer,
                                                     VkImage dstImage, VkImageLayout dstImageLayout,
                                                     uint32_t regionCount, const VkBufferImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBufferToImage");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toCopy2(pRegions[i]));
  recordBufferImage(cb, srcBuffer, dstImage, dstImageLayout, std::move(regions), true, kBufferToImage);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBufferToImage2(VkCommandBuffer commandBuffer,
                                                      const VkCopyBufferToImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBufferToImage2");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBufferImage(cb, pInfo->srcBuffer, pInfo->dstImage, pInfo->dstImageLayout, std::move(regions), true,
                    kBufferToImage2);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer(VkCommandBuffer commandBuffer, VkImage srcImage,
                                                     VkImageLayout srcImageLayout, VkBuffer dstBuffer,
                                                     uint32_t regionCount, const VkBufferImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toCopy2(pRegions[i]));
  recordBufferImage(cb, dstBuffer, srcImage, srcImageLayout, std::move(regions), false, kImageToBuffer);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer2(VkCommandBuffer commandBuffer,
                                                      const VkCopyImageToBufferInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer2");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBufferImage(cb, pInfo->dstBuffer, pInfo->srcImage, pInfo->srcImageLayout, std::move(regions), false,
                    kImageToBuffer2);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImage(VkCommandBuffer commandBuffer, VkImage srcImage,
                                             VkImageLayout srcImageLayout, VkImage dstImage,
                                             VkImageLayout dstImageLayout, uint32_t regionCount,
                                             const VkImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImage");
  if (!cb) return;
  std::vector<VkImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) {
    const VkImageCopy& r = pRegions[i];
    regions.push_back({VK_STRUCTURE_TYPE_IMAGE_COPY_2, nullptr, r.srcSubresource, r.srcOffset, r.dstSubresource,
                       r.dstOffset, r.extent});
  }
  recordImageCopy(cb, srcImage, srcImageLayout, dstImage, dstImageLayout, std::move(regions), kCopySrc, kCopyDst,
                  "VUID-vkCmdCopyImage-srcImage-01548", "VUID-vkCmdCopyImage-srcImage-07744");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImage2(VkCommandBuffer commandBuffer, const VkCopyImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImage2");
  if (!cb) return;
  std::vector<VkImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordImageCopy(cb, pInfo->srcImage, pInfo->srcImageLayout, pInfo->dstImage, pInfo->dstImageLayout,
                  std::move(regions), kCopySrc2, kCopyDst2, "VUID-VkCopyImageInfo2-srcImage-01548",
                  "VUID-VkCopyImageInfo2-srcImage-07744");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdClearColorImage(VkCommandBuffer commandBuffer, VkImage image,
                                                   VkImageLayout imageLayout, const VkClearColorValue* pColor,
                                                   uint32_t rangeCount, const VkImageSubresourceRange* pRanges) {
  const char* fn = "vkCmdClearColorImage";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  Image* img = transferImage(cb, image, true, imageLayout, kClear);
  if (!img) return;
  std::vector<VkImageSubresourceRange> ranges(pRanges, pRanges + rangeCount);
  for (uint32_t i = 0; i < rangeCount; ++i) {
    const VkImageSubresourceRange& r = ranges[i];
    uint32_t levels = r.levelCount == VK_REMAINING_MIP_LEVELS
                          ? img->mipLevels - std::min(r.baseMipLevel, img->mipLevels)
                          : r.levelCount;
    uint32_t layers = r.layerCount == VK_REMAINING_ARRAY_LAYERS
                          ? img->arrayLayers - std::min(r.baseArrayLayer, img->arrayLayers)
                          : r.layerCount;
    // VUID-vkCmdClearColorImage-aspectMask-02498 / baseMipLevel-01470 / pRanges-01692 / baseArrayLayer-01472 /
    // pRanges-01693
    const char* vuid = r.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT ? "VUID-vkCmdClearColorImage-aspectMask-02498"
                       : r.baseMipLevel >= img->mipLevels        ? "VUID-vkCmdClearColorImage-baseMipLevel-01470"
                       : levels == 0 || uint64_t(r.baseMipLevel) + levels > img->mipLevels
                           ? "VUID-vkCmdClearColorImage-pRanges-01692"
                       : r.baseArrayLayer >= img->arrayLayers ? "VUID-vkCmdClearColorImage-baseArrayLayer-01472"
                       : layers == 0 || uint64_t(r.baseArrayLayer) + layers > img->arrayLayers
                           ? "VUID-vkCmdClearColorImage-pRanges-01693"
                           : nullptr;
    if (vuid) {
      report(
          img, Severity::Error, vuid,
          "%s: pRanges[%u] (aspect 0x%x, mips [%u, +%u), layers [%u, +%u)) is outside the image (%u mips, %u layers)",
          fn, i, r.aspectMask, r.baseMipLevel, r.levelCount, r.baseArrayLayer, r.layerCount, img->mipLevels,
          img->arrayLayers);
      return;
    }
  }
  uint8_t texel[16];
  if (!encodeClearColor(*img->formatInfo, *pColor, texel)) {
    report(img, Severity::Error, nullptr, "%s: vkrt cannot encode a clear color for format %d", fn, (int)img->format);
    return;
  }
  std::vector<uint8_t> encoded(texel, texel + img->formatInfo->texelSize);
  cb->record([img, encoded = std::move(encoded), ranges = std::move(ranges)](ExecState&) {
    for (const auto& r : ranges) clearImage(*img, encoded.data(), r);
  });
}

// vkCmdResolveImage / vkCmdResolveImage2 (and vkCmdResolveImage2KHR, VK_KHR_copy_commands2): a multisampled image
// resolved into a single-sampled one. Every vkrt image has one sample (vkGetPhysicalDeviceImageFormatProperties
// reports sampleCounts VK_SAMPLE_COUNT_1_BIT for every format), so no call can name a valid source: each reports
// that its source is not multisampled and records nothing.
static void reportResolve(CommandBuffer* cb, VkImage srcImage, const char* fn, const char* vuid) {
  Image* src = fromHandle<Image>(srcImage);
  report(src ? static_cast<const Object*>(src) : cb, Severity::Error, vuid,
         "%s: srcImage 0x%llx has VK_SAMPLE_COUNT_1_BIT, but a resolve's source must be multisampled (vkrt's "
         "images have one sample)",
         fn, (unsigned long long)rawHandle(srcImage));
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResolveImage(VkCommandBuffer commandBuffer, VkImage srcImage, VkImageLayout, VkImage,
                                                VkImageLayout, uint32_t, const VkImageResolve*) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResolveImage");
  if (!cb) return;
  // VUID-vkCmdResolveImage-srcImage-00257
  reportResolve(cb, srcImage, "vkCmdResolveImage", "VUID-vkCmdResolveImage-srcImage-00257");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResolveImage2(VkCommandBuffer commandBuffer, const VkResolveImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResolveImage2");
  if (!cb) return;
  // VUID-VkResolveImageInfo2-srcImage-00257
  reportResolve(cb, pInfo->srcImage, "vkCmdResolveImage2", "VUID-VkResolveImageInfo2-srcImage-00257");
}

}  // extern "C"
