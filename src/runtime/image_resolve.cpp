// vkCmdResolveImage(2) and vkCmdClearDepthStencilImage, with the resolve arithmetic the render passes' resolves
// share (gfx/rendering.cpp): image_copy.hpp declares resolveImage, resolveColorPixel and resolveDepthStencilPixel.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "runtime/command_buffer.hpp"
#include "runtime/image.hpp"
#include "runtime/image_commands.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

void resolveColorPixel(const FormatInfo& f, const uint8_t* src, uint32_t samples, uint8_t* dst) {
  if (f.type == NumericType::UInt || f.type == NumericType::SInt || samples == 1) {
    std::memcpy(dst, src, f.texelSize);  // integers: sample 0 ("Multisample Resolve" leaves the choice open)
    return;
  }
  // Floats and normalized values (sRGB decoded to linear by decodeTexel): the average of the samples.
  float sum[4] = {0, 0, 0, 0};
  for (uint32_t s = 0; s < samples; ++s) {
    uint32_t w[4];
    decodeTexel(f, src + size_t(s) * f.texelSize, w);
    for (int c = 0; c < 4; ++c) {
      float v;
      std::memcpy(&v, &w[c], 4);
      sum[c] += v;
    }
  }
  uint32_t out[4];
  for (int c = 0; c < 4; ++c) {
    const float v = sum[c] / float(samples);
    std::memcpy(&out[c], &v, 4);
  }
  encodeTexel(f, out, dst);
}

void resolveDepthStencilPixel(VkFormat format, VkImageAspectFlags aspect, VkResolveModeFlagBits mode,
                              const uint8_t* src, uint32_t samples, uint8_t* dst) {
  const FormatInfo& f = *aspectFormatInfo(format, aspect);
  const uint32_t t = f.texelSize;
  if (mode == VK_RESOLVE_MODE_NONE) return;
  uint32_t w[4];
  decodeTexel(f, src, w);
  if (mode == VK_RESOLVE_MODE_SAMPLE_ZERO_BIT || samples == 1) {
    encodeTexel(f, w, dst);
    return;
  }
  const bool isFloat = aspect == VK_IMAGE_ASPECT_DEPTH_BIT;  // depth decodes to a float, stencil to an integer
  double acc = 0;
  for (uint32_t s = 0; s < samples; ++s) {
    decodeTexel(f, src + size_t(s) * t, w);
    double v;
    if (isFloat) {
      float x;
      std::memcpy(&x, &w[0], 4);
      v = x;
    } else {
      v = w[0];
    }
    if (s == 0 || mode == VK_RESOLVE_MODE_AVERAGE_BIT)
      acc = s == 0 ? v : acc + v;
    else
      acc = mode == VK_RESOLVE_MODE_MIN_BIT ? std::min(acc, v) : std::max(acc, v);
  }
  if (mode == VK_RESOLVE_MODE_AVERAGE_BIT) acc /= samples;
  uint32_t out[4] = {};
  if (isFloat) {
    const float x = float(acc);
    std::memcpy(&out[0], &x, 4);
  } else {
    out[0] = uint32_t(acc);
  }
  encodeTexel(f, out, dst);
}

void resolveImage(const Image& src, const Image& dst, const VkImageResolve2& r) {
  for (uint32_t l = 0; l < r.srcSubresource.layerCount; ++l)
    for (uint32_t y = 0; y < r.extent.height; ++y)
      for (uint32_t x = 0; x < r.extent.width; ++x)
        resolveColorPixel(*src.formatInfo,
                          src.texel(r.srcSubresource.mipLevel, r.srcSubresource.baseArrayLayer + l,
                                    uint32_t(r.srcOffset.x) + x, uint32_t(r.srcOffset.y) + y, 0),
                          src.samples,
                          dst.texel(r.dstSubresource.mipLevel, r.dstSubresource.baseArrayLayer + l,
                                    uint32_t(r.dstOffset.x) + x, uint32_t(r.dstOffset.y) + y, 0));
}

}  // namespace vkrt

using namespace vkrt;

namespace {

constexpr Vuids kResolveSrc{"vkCmdResolveImage",
                            "VUID-vkCmdResolveImage-srcImage-06762",
                            "VUID-vkCmdResolveImage-srcImage-00256",
                            "VUID-vkCmdResolveImage-srcImageLayout-01400",
                            "VUID-vkCmdResolveImage-srcSubresource-01709",
                            "VUID-vkCmdResolveImage-srcSubresource-01711",
                            "VUID-vkCmdResolveImage-srcOffset-00269",
                            "VUID-VkImageResolve-aspectMask-00266"};
constexpr Vuids kResolveDst{"vkCmdResolveImage",
                            "VUID-vkCmdResolveImage-dstImage-06764",
                            "VUID-vkCmdResolveImage-dstImage-00258",
                            "VUID-vkCmdResolveImage-dstImageLayout-01401",
                            "VUID-vkCmdResolveImage-dstSubresource-01710",
                            "VUID-vkCmdResolveImage-dstSubresource-01712",
                            "VUID-vkCmdResolveImage-dstOffset-00274",
                            "VUID-VkImageResolve-aspectMask-00266"};
constexpr Vuids kResolveSrc2{"vkCmdResolveImage2",
                             "VUID-VkResolveImageInfo2-srcImage-06762",
                             "VUID-VkResolveImageInfo2-srcImage-00256",
                             "VUID-VkResolveImageInfo2-srcImageLayout-01400",
                             "VUID-VkResolveImageInfo2-srcSubresource-01709",
                             "VUID-VkResolveImageInfo2-srcSubresource-01711",
                             "VUID-VkResolveImageInfo2-srcOffset-00269",
                             "VUID-VkImageResolve2-aspectMask-00266"};
constexpr Vuids kResolveDst2{"vkCmdResolveImage2",
                             "VUID-VkResolveImageInfo2-dstImage-06764",
                             "VUID-VkResolveImageInfo2-dstImage-00258",
                             "VUID-VkResolveImageInfo2-dstImageLayout-01401",
                             "VUID-VkResolveImageInfo2-dstSubresource-01710",
                             "VUID-VkResolveImageInfo2-dstSubresource-01712",
                             "VUID-VkResolveImageInfo2-dstOffset-00274",
                             "VUID-VkImageResolve2-aspectMask-00266"};

void recordResolve(CommandBuffer* cb, VkImage srcH, VkImageLayout srcLayout, VkImage dstH, VkImageLayout dstLayout,
                   std::vector<VkImageResolve2> regions, bool two) {
  const Vuids& vs = two ? kResolveSrc2 : kResolveSrc;
  const Vuids& vd = two ? kResolveDst2 : kResolveDst;
  const char* fn = vs.fn;
  // VUID-vkCmdResolveImage-renderpass
  if (!cb->outsideRenderPass(fn, two ? "VUID-vkCmdResolveImage2-renderpass" : "VUID-vkCmdResolveImage-renderpass"))
    return;
  Image* src = transferImage(cb, srcH, false, srcLayout, vs);
  Image* dst = src ? transferImage(cb, dstH, true, dstLayout, vd) : nullptr;
  if (!src || !dst) return;
  // VUID-vkCmdResolveImage-srcImage-00257 / dstImage-00259: multisampled into single-sampled
  if (src->samples == 1 || dst->samples != 1) {
    const bool s = src->samples == 1;
    report(s ? src : dst, Severity::Error,
           s ? (two ? "VUID-VkResolveImageInfo2-srcImage-00257" : "VUID-vkCmdResolveImage-srcImage-00257")
             : (two ? "VUID-VkResolveImageInfo2-dstImage-00259" : "VUID-vkCmdResolveImage-dstImage-00259"),
           "%s: srcImage has %u samples and dstImage %u (a multisampled source into a single-sampled destination)", fn,
           src->samples, dst->samples);
    return;
  }
  // VUID-vkCmdResolveImage-srcImage-01386: the same format
  if (src->format != dst->format) {
    report(dst, Severity::Error,
           two ? "VUID-VkResolveImageInfo2-srcImage-01386" : "VUID-vkCmdResolveImage-srcImage-01386",
           "%s: srcImage format %d differs from dstImage format %d", fn, (int)src->format, (int)dst->format);
    return;
  }
  // VUID-vkCmdResolveImage-dstImage-02003: COLOR_ATTACHMENT format feature
  if (!(formatFeatures(dst->format) & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT)) {
    report(dst, Severity::Error,
           two ? "VUID-VkResolveImageInfo2-dstImage-02003" : "VUID-vkCmdResolveImage-dstImage-02003",
           "%s: dstImage format %d lacks VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT", fn, (int)dst->format);
    return;
  }
  for (uint32_t i = 0; i < regions.size(); ++i) {
    const VkImageResolve2& r = regions[i];
    // VUID-VkImageResolve-aspectMask-00266: color only
    if (r.srcSubresource.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT ||
        r.dstSubresource.aspectMask != VK_IMAGE_ASPECT_COLOR_BIT) {
      report(dst, Severity::Error, vs.aspect, "%s: pRegions[%u] aspects 0x%x / 0x%x are not VK_IMAGE_ASPECT_COLOR_BIT",
             fn, i, r.srcSubresource.aspectMask, r.dstSubresource.aspectMask);
      return;
    }
    // VUID-VkImageResolve-layerCount-00267: srcSubresource and dstSubresource layer counts match
    if (r.srcSubresource.layerCount != r.dstSubresource.layerCount) {
      report(dst, Severity::Error,
             two ? "VUID-VkImageResolve2-layerCount-00267" : "VUID-VkImageResolve-layerCount-00267",
             "%s: pRegions[%u] resolves %u layers into %u", fn, i, r.srcSubresource.layerCount,
             r.dstSubresource.layerCount);
      return;
    }
    if (!regionInImage(*src, r.srcSubresource, r.srcOffset, r.extent, i, "srcSubresource", vs) ||
        !regionInImage(*dst, r.dstSubresource, r.dstOffset, r.extent, i, "dstSubresource", vd))
      return;
  }
  cb->record([src, dst, regions = std::move(regions)](ExecState&) {
    for (const VkImageResolve2& r : regions) resolveImage(*src, *dst, r);
  });
}

VkImageResolve2 toResolve2(const VkImageResolve& r) {
  return {VK_STRUCTURE_TYPE_IMAGE_RESOLVE_2,
          nullptr,
          r.srcSubresource,
          r.srcOffset,
          r.dstSubresource,
          r.dstOffset,
          r.extent};
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResolveImage(VkCommandBuffer commandBuffer, VkImage srcImage,
                                                VkImageLayout srcImageLayout, VkImage dstImage,
                                                VkImageLayout dstImageLayout, uint32_t regionCount,
                                                const VkImageResolve* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResolveImage");
  if (!cb) return;
  std::vector<VkImageResolve2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toResolve2(pRegions[i]));
  recordResolve(cb, srcImage, srcImageLayout, dstImage, dstImageLayout, std::move(regions), false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResolveImage2(VkCommandBuffer commandBuffer, const VkResolveImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResolveImage2");
  if (!cb) return;
  std::vector<VkImageResolve2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordResolve(cb, pInfo->srcImage, pInfo->srcImageLayout, pInfo->dstImage, pInfo->dstImageLayout, std::move(regions),
                true);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdClearDepthStencilImage(VkCommandBuffer commandBuffer, VkImage image,
                                                          VkImageLayout imageLayout,
                                                          const VkClearDepthStencilValue* pDepthStencil,
                                                          uint32_t rangeCount, const VkImageSubresourceRange* pRanges) {
  static constexpr Vuids kClearDs{"vkCmdClearDepthStencilImage", "VUID-vkCmdClearDepthStencilImage-pRanges-02660",
                                  "VUID-vkCmdClearDepthStencilImage-image-00010",
                                  "VUID-vkCmdClearDepthStencilImage-imageLayout-00012"};
  const char* fn = kClearDs.fn;
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdClearDepthStencilImage-renderpass
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdClearDepthStencilImage-renderpass")) return;
  // VUID-vkCmdClearDepthStencilImage-pRanges-02659 (stencil, one usage) / 02658 (stencil, separate stencil usage)
  static constexpr AspectUsageVuids kClearDsAspects{"VUID-vkCmdClearDepthStencilImage-pRanges-02659",
                                                    "VUID-vkCmdClearDepthStencilImage-pRanges-02658",
                                                    "VUID-vkCmdClearDepthStencilImage-pRanges-02660"};
  VkImageAspectFlags aspects = 0;
  for (uint32_t i = 0; i < rangeCount; ++i) aspects |= pRanges[i].aspectMask;
  Image* img = transferImage(cb, image, true, imageLayout, kClearDs, aspects, &kClearDsAspects);
  if (!img) return;
  // VUID-vkCmdClearDepthStencilImage-image-00014: a depth/stencil format
  if (!(img->aspects & (VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT))) {
    report(img, Severity::Error, "VUID-vkCmdClearDepthStencilImage-image-00014",
           "%s: the image's format %d is not a depth/stencil format", fn, (int)img->format);
    return;
  }
  // VUID-vkCmdClearDepthStencilImage-pDepthStencil-00022 (depth in [0, 1] without VK_EXT_depth_range_unrestricted)
  if (!(pDepthStencil->depth >= 0.0f && pDepthStencil->depth <= 1.0f)) {
    report(img, Severity::Error, "VUID-VkClearDepthStencilValue-depth-00022", "%s: depth %f is outside [0, 1]", fn,
           double(pDepthStencil->depth));
    return;
  }
  std::vector<VkImageSubresourceRange> ranges(pRanges, pRanges + rangeCount);
  for (uint32_t i = 0; i < rangeCount; ++i) {
    const VkImageSubresourceRange& r = ranges[i];
    const uint32_t levels = r.levelCount == VK_REMAINING_MIP_LEVELS
                                ? img->mipLevels - std::min(r.baseMipLevel, img->mipLevels)
                                : r.levelCount;
    const uint32_t layers = r.layerCount == VK_REMAINING_ARRAY_LAYERS
                                ? img->arrayLayers - std::min(r.baseArrayLayer, img->arrayLayers)
                                : r.layerCount;
    // VUID-vkCmdClearDepthStencilImage-aspectMask-02824/02825/02826 (only the image's depth/stencil aspects) /
    // baseMipLevel-01474 / pRanges-01694 / baseArrayLayer-01476 / pRanges-01695
    const VkImageAspectFlags ds = VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    const char* vuid = !r.aspectMask || (r.aspectMask & ~ds) ? "VUID-vkCmdClearDepthStencilImage-aspectMask-02824"
                       : (r.aspectMask & VK_IMAGE_ASPECT_DEPTH_BIT) && !(img->aspects & VK_IMAGE_ASPECT_DEPTH_BIT)
                           ? "VUID-vkCmdClearDepthStencilImage-image-02826"
                       : (r.aspectMask & VK_IMAGE_ASPECT_STENCIL_BIT) && !(img->aspects & VK_IMAGE_ASPECT_STENCIL_BIT)
                           ? "VUID-vkCmdClearDepthStencilImage-image-02825"
                       : r.baseMipLevel >= img->mipLevels ? "VUID-vkCmdClearDepthStencilImage-baseMipLevel-01474"
                       : levels == 0 || uint64_t(r.baseMipLevel) + levels > img->mipLevels
                           ? "VUID-vkCmdClearDepthStencilImage-pRanges-01694"
                       : r.baseArrayLayer >= img->arrayLayers ? "VUID-vkCmdClearDepthStencilImage-baseArrayLayer-01476"
                       : layers == 0 || uint64_t(r.baseArrayLayer) + layers > img->arrayLayers
                           ? "VUID-vkCmdClearDepthStencilImage-pRanges-01695"
                           : nullptr;
    if (vuid) {
      report(img, Severity::Error, vuid,
             "%s: pRanges[%u] (aspect 0x%x, mips [%u, +%u), layers [%u, +%u)) does not fit the image (aspects 0x%x, "
             "%u mips, %u layers)",
             fn, i, r.aspectMask, r.baseMipLevel, r.levelCount, r.baseArrayLayer, r.layerCount, img->aspects,
             img->mipLevels, img->arrayLayers);
      return;
    }
  }
  cb->record([img, value = *pDepthStencil, ranges = std::move(ranges)](ExecState&) {
    for (const auto& r : ranges) clearDepthStencilImage(*img, value, r);
  });
}

}  // extern "C"
