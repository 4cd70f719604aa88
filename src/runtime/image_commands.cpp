// Image transfer commands: vkCmdCopyBufferToImage(2), vkCmdCopyImageToBuffer(2), vkCmdCopyImage(2),
// vkCmdClearColorImage. Each validates its regions (reporting the VUID and recording nothing when one is
// invalid) and records a closure that runs the routines of runtime/image_copy.hpp.
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

bool layoutOk(VkImageLayout l, bool dst) {
  return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHARED_PRESENT_KHR ||
         l == (dst ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

// A live image bound to memory, with the transfer usage; reports otherwise.
Image* transferImage(CommandBuffer* cb, VkImage h, bool dst, VkImageLayout layout, const char* fn, const char* vuidPrefix) {
  Image* img = fromHandle<Image>(h);
  if (!img) {
    report(cb, Severity::Error, nullptr, "%s: %s 0x%llx is not a live VkImage", fn, dst ? "dstImage" : "srcImage",
           (ull)rawHandle(h));
    return nullptr;
  }
  std::string prefix = vuidPrefix;
  if (!(img->usage & (dst ? VK_IMAGE_USAGE_TRANSFER_DST_BIT : VK_IMAGE_USAGE_TRANSFER_SRC_BIT))) {
    std::string v = prefix + (dst ? "dstImage-00177" : "srcImage-00186");
    report(img, Severity::Error, v.c_str(), "%s: the image was created without VK_IMAGE_USAGE_TRANSFER_%s_BIT (usage 0x%x)",
           fn, dst ? "DST" : "SRC", img->usage);
    return nullptr;
  }
  if (!img->memory) {
    std::string v = prefix + (dst ? "dstImage-07966" : "srcImage-07966");
    report(img, Severity::Error, v.c_str(), "%s: the image is not bound to memory", fn);
    return nullptr;
  }
  if (!layoutOk(layout, dst)) {
    std::string v = prefix + (dst ? "dstImageLayout-01395" : "srcImageLayout-01397");
    report(img, Severity::Error, v.c_str(), "%s: image layout %d is not GENERAL or TRANSFER_%s_OPTIMAL", fn, (int)layout,
           dst ? "DST" : "SRC");
    return nullptr;
  }
  return img;
}

// Checks that [offset, offset + extent) of (mip, layers) lies inside the image.
bool regionInImage(const Image& img, const VkImageSubresourceLayers& sub, VkOffset3D off, VkExtent3D ext,
                   const char* fn, uint32_t index, const char* what, const char* vuid) {
  if (sub.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT) {
    report(&img, Severity::Error, vuid, "%s: pRegions[%u].%s aspectMask 0x%x is not VK_IMAGE_ASPECT_COLOR_BIT", fn,
           index, what, sub.aspectMask);
    return false;
  }
  if (sub.mipLevel >= img.mipLevels || sub.layerCount == 0 || sub.baseArrayLayer >= img.arrayLayers ||
      sub.layerCount > img.arrayLayers - sub.baseArrayLayer) {
    report(&img, Severity::Error, vuid, "%s: pRegions[%u].%s (mip %u, layers [%u, +%u)) is outside the image (%u mips, %u layers)",
           fn, index, what, sub.mipLevel, sub.baseArrayLayer, sub.layerCount, img.mipLevels, img.arrayLayers);
    return false;
  }
  VkExtent3D m = img.mips[sub.mipLevel].extent;
  auto fits = [](int32_t o, uint32_t e, uint32_t size) { return o >= 0 && e > 0 && uint64_t(o) + e <= size; };
  if (!fits(off.x, ext.width, m.width) || !fits(off.y, ext.height, m.height) || !fits(off.z, ext.depth, m.depth)) {
    report(&img, Severity::Error, vuid,
           "%s: pRegions[%u] offset (%d, %d, %d) extent (%u, %u, %u) exceeds mip %u's extent (%u, %u, %u)", fn, index,
           off.x, off.y, off.z, ext.width, ext.height, ext.depth, sub.mipLevel, m.width, m.height, m.depth);
    return false;
  }
  return true;
}

void recordBufferImage(CommandBuffer* cb, VkBuffer bufferH, VkImage imageH, VkImageLayout layout, uint32_t count,
                       std::vector<VkBufferImageCopy2> regions, bool toImage, const char* fn, const char* prefix) {
  Buffer* buf = fromHandle<Buffer>(bufferH);
  if (!buf || !buf->memory) {
    report(cb, Severity::Error, nullptr, "%s: buffer 0x%llx is not a live VkBuffer bound to memory", fn,
           (ull)rawHandle(bufferH));
    return;
  }
  VkBufferUsageFlags need = toImage ? VK_BUFFER_USAGE_TRANSFER_SRC_BIT : VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (!(buf->usage & need)) {
    std::string v = std::string(prefix) + (toImage ? "srcBuffer-00174" : "dstBuffer-00191");
    report(buf, Severity::Error, v.c_str(), "%s: the buffer lacks VK_BUFFER_USAGE_TRANSFER_%s_BIT (usage 0x%x)", fn,
           toImage ? "SRC" : "DST", buf->usage);
    return;
  }
  Image* img = transferImage(cb, imageH, toImage, layout, fn, prefix);
  if (!img) return;
  const uint32_t t = img->formatInfo->texelSize;
  for (uint32_t i = 0; i < count; ++i) {
    const VkBufferImageCopy2& r = regions[i];
    std::string v = std::string(prefix) + (toImage ? "pRegions-06217" : "pRegions-06220");
    if (!regionInImage(*img, r.imageSubresource, r.imageOffset, r.imageExtent, fn, i, "imageSubresource", v.c_str()))
      return;
    // VUID-VkBufferImageCopy-bufferRowLength-09101 / bufferImageHeight-09102
    if ((r.bufferRowLength && r.bufferRowLength < r.imageExtent.width) ||
        (r.bufferImageHeight && r.bufferImageHeight < r.imageExtent.height)) {
      report(buf, Severity::Error, "VUID-VkBufferImageCopy-bufferRowLength-09101",
             "%s: pRegions[%u] bufferRowLength %u / bufferImageHeight %u is smaller than the extent (%u, %u)", fn, i,
             r.bufferRowLength, r.bufferImageHeight, r.imageExtent.width, r.imageExtent.height);
      return;
    }
    // VUID-...-bufferOffset-07975: a multiple of the texel size
    if (r.bufferOffset % t) {
      std::string vo = std::string(prefix) + "bufferOffset-07975";
      report(buf, Severity::Error, vo.c_str(), "%s: pRegions[%u].bufferOffset %llu is not a multiple of the %u-byte texel",
             fn, i, (ull)r.bufferOffset, t);
      return;
    }
    VkDeviceSize need = bufferFootprint(r, t);
    // VUID-vkCmdCopyBufferToImage-pRegions-00171 / vkCmdCopyImageToBuffer-pRegions-00183
    if (r.bufferOffset > buf->size || need > buf->size - r.bufferOffset) {
      std::string vb = std::string(prefix) + (toImage ? "pRegions-00171" : "pRegions-00183");
      report(buf, Severity::Error, vb.c_str(), "%s: pRegions[%u] needs %llu bytes at bufferOffset %llu; the buffer has %llu",
             fn, i, (ull)need, (ull)r.bufferOffset, (ull)buf->size);
      return;
    }
  }
  cb->record([buf, img, regions = std::move(regions), toImage](ExecState&) {
    for (const VkBufferImageCopy2& r : regions) copyBufferImage(*img, buf->data(), r, toImage);
  });
}

VkBufferImageCopy2 toCopy2(const VkBufferImageCopy& r) {
  return {VK_STRUCTURE_TYPE_BUFFER_IMAGE_COPY_2, nullptr, r.bufferOffset, r.bufferRowLength, r.bufferImageHeight,
          r.imageSubresource, r.imageOffset, r.imageExtent};
}

void recordImageCopy(CommandBuffer* cb, VkImage srcH, VkImageLayout srcLayout, VkImage dstH, VkImageLayout dstLayout,
                     std::vector<VkImageCopy2> regions, const char* fn, const char* prefix) {
  Image* src = transferImage(cb, srcH, false, srcLayout, fn, prefix);
  Image* dst = src ? transferImage(cb, dstH, true, dstLayout, fn, prefix) : nullptr;
  if (!src || !dst) return;
  // VUID-vkCmdCopyImage-srcImage-01548: size-compatible formats
  if (src->formatInfo->texelSize != dst->formatInfo->texelSize) {
    std::string v = std::string(prefix) + "srcImage-01548";
    report(dst, Severity::Error, v.c_str(), "%s: formats %d and %d have different texel sizes (%u, %u)", fn,
           (int)src->format, (int)dst->format, src->formatInfo->texelSize, dst->formatInfo->texelSize);
    return;
  }
  for (uint32_t i = 0; i < regions.size(); ++i) {
    const VkImageCopy2& r = regions[i];
    std::string vs = std::string(prefix) + "pRegions-00122", vd = std::string(prefix) + "pRegions-00123";
    if (!regionInImage(*src, r.srcSubresource, r.srcOffset, r.extent, fn, i, "srcSubresource", vs.c_str()) ||
        !regionInImage(*dst, r.dstSubresource, r.dstOffset, r.extent, fn, i, "dstSubresource", vd.c_str()))
      return;
    if (r.srcSubresource.layerCount != r.dstSubresource.layerCount) {
      std::string v = std::string(prefix) + "srcImage-07744";
      report(dst, Severity::Error, v.c_str(), "%s: pRegions[%u] copies %u layers into %u", fn, i,
             r.srcSubresource.layerCount, r.dstSubresource.layerCount);
      return;
    }
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
  recordBufferImage(cb, srcBuffer, dstImage, dstImageLayout, regionCount, std::move(regions), true,
                    "vkCmdCopyBufferToImage", "VUID-vkCmdCopyBufferToImage-");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBufferToImage2(VkCommandBuffer commandBuffer,
                                                      const VkCopyBufferToImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBufferToImage2");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBufferImage(cb, pInfo->srcBuffer, pInfo->dstImage, pInfo->dstImageLayout, pInfo->regionCount,
                    std::move(regions), true, "vkCmdCopyBufferToImage2", "VUID-VkCopyBufferToImageInfo2-");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer(VkCommandBuffer commandBuffer, VkImage srcImage,
                                                     VkImageLayout srcImageLayout, VkBuffer dstBuffer,
                                                     uint32_t regionCount, const VkBufferImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toCopy2(pRegions[i]));
  recordBufferImage(cb, dstBuffer, srcImage, srcImageLayout, regionCount, std::move(regions), false,
                    "vkCmdCopyImageToBuffer", "VUID-vkCmdCopyImageToBuffer-");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer2(VkCommandBuffer commandBuffer,
                                                      const VkCopyImageToBufferInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer2");
  if (!cb) return;
  std::vector<VkBufferImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBufferImage(cb, pInfo->dstBuffer, pInfo->srcImage, pInfo->srcImageLayout, pInfo->regionCount,
                    std::move(regions), false, "vkCmdCopyImageToBuffer2", "VUID-VkCopyImageToBufferInfo2-");
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
  recordImageCopy(cb, srcImage, srcImageLayout, dstImage, dstImageLayout, std::move(regions), "vkCmdCopyImage",
                  "VUID-vkCmdCopyImage-");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImage2(VkCommandBuffer commandBuffer, const VkCopyImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImage2");
  if (!cb) return;
  std::vector<VkImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordImageCopy(cb, pInfo->srcImage, pInfo->srcImageLayout, pInfo->dstImage, pInfo->dstImageLayout,
                  std::move(regions), "vkCmdCopyImage2", "VUID-VkCopyImageInfo2-");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdClearColorImage(VkCommandBuffer commandBuffer, VkImage image,
                                                   VkImageLayout imageLayout, const VkClearColorValue* pColor,
                                                   uint32_t rangeCount, const VkImageSubresourceRange* pRanges) {
  const char* fn = "vkCmdClearColorImage";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  Image* img = transferImage(cb, image, true, imageLayout, fn, "VUID-vkCmdClearColorImage-");
  if (!img) return;
  std::vector<VkImageSubresourceRange> ranges(pRanges, pRanges + rangeCount);
  for (uint32_t i = 0; i < rangeCount; ++i) {
    const VkImageSubresourceRange& r = ranges[i];
    uint32_t levels = r.levelCount == VK_REMAINING_MIP_LEVELS ? img->mipLevels - std::min(r.baseMipLevel, img->mipLevels)
                                                              : r.levelCount;
    uint32_t layers = r.layerCount == VK_REMAINING_ARRAY_LAYERS
                          ? img->arrayLayers - std::min(r.baseArrayLayer, img->arrayLayers)
                          : r.layerCount;
    // VUID-vkCmdClearColorImage-baseMipLevel-01470 / pRanges-01692 / baseArrayLayer-01472 / pRanges-01693
    if (r.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT || r.baseMipLevel >= img->mipLevels || levels == 0 ||
        uint64_t(r.baseMipLevel) + levels > img->mipLevels || r.baseArrayLayer >= img->arrayLayers || layers == 0 ||
        uint64_t(r.baseArrayLayer) + layers > img->arrayLayers) {
      report(img, Severity::Error, "VUID-vkCmdClearColorImage-baseMipLevel-01470",
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

}  // extern "C"
