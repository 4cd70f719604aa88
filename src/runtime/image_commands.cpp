// Image transfer commands: vkCmdCopyBufferToImage(2), vkCmdCopyImageToBuffer(2), vkCmdCopyImage(2),
// vkCmdBlitImage(2), vkCmdClearColorImage. Each validates its regions (reporting the VUID and recording nothing when
// one is invalid) and records a closure that runs the routines of runtime/image_copy.hpp and image_blit.hpp.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/image.hpp"
#include "runtime/image_blit.hpp"
#include "runtime/image_commands.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/memory.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;

namespace {

using ull = unsigned long long;

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

// vkCmdBlitImage(2): the image tables (bounds unused: blit regions are checked offset by offset), then the rules
// of blits alone.
struct BlitVuids {
  Vuids src, dst;
  const char* sint;         // signed integer with signed integer only
  const char* uint;         // unsigned integer with unsigned integer only
  const char* linear;       // VK_FILTER_LINEAR needs SAMPLED_IMAGE_FILTER_LINEAR
  const char* cubic;        // VK_FILTER_CUBIC_EXT needs SAMPLED_IMAGE_FILTER_CUBIC
  const char* filter;       // a valid VkFilter
  const char* aspects;      // src and dst aspects match
  const char* layerCounts;  // src and dst layer counts match
  const char* threeD;       // 3D: base layer 0, one layer
  const char* srcX;         // srcOffsets x, y, z inside the mip
  const char* srcY;
  const char* srcZ;
  const char* src1D;  // 1D: srcOffsets y 0 and 1
  const char* src2D;  // 1D/2D: srcOffsets z 0 and 1
  const char* dstX;
  const char* dstY;
  const char* dstZ;
  const char* dst1D;
  const char* dst2D;
  const char* overlap;  // destination regions overlap sampled source texels
};

constexpr BlitVuids kBlit{{"vkCmdBlitImage", "VUID-vkCmdBlitImage-srcImage-00219", "VUID-vkCmdBlitImage-srcImage-00220",
                           "VUID-vkCmdBlitImage-srcImageLayout-01398", "VUID-vkCmdBlitImage-srcSubresource-01705",
                           "VUID-vkCmdBlitImage-srcSubresource-01707", nullptr, "VUID-vkCmdBlitImage-aspectMask-00241"},
                          {"vkCmdBlitImage", "VUID-vkCmdBlitImage-dstImage-00224", "VUID-vkCmdBlitImage-dstImage-00225",
                           "VUID-vkCmdBlitImage-dstImageLayout-01399", "VUID-vkCmdBlitImage-dstSubresource-01706",
                           "VUID-vkCmdBlitImage-dstSubresource-01708", nullptr, "VUID-vkCmdBlitImage-aspectMask-00242"},
                          "VUID-vkCmdBlitImage-srcImage-00229",
                          "VUID-vkCmdBlitImage-srcImage-00230",
                          "VUID-vkCmdBlitImage-filter-02001",
                          "VUID-vkCmdBlitImage-filter-02002",
                          "VUID-vkCmdBlitImage-filter-parameter",
                          "VUID-VkImageBlit-aspectMask-00238",
                          "VUID-VkImageBlit-layerCount-00239",
                          "VUID-vkCmdBlitImage-srcImage-00240",
                          "VUID-vkCmdBlitImage-srcOffset-00243",
                          "VUID-vkCmdBlitImage-srcOffset-00244",
                          "VUID-vkCmdBlitImage-srcOffset-00246",
                          "VUID-vkCmdBlitImage-srcImage-00245",
                          "VUID-vkCmdBlitImage-srcImage-00247",
                          "VUID-vkCmdBlitImage-dstOffset-00248",
                          "VUID-vkCmdBlitImage-dstOffset-00249",
                          "VUID-vkCmdBlitImage-dstOffset-00251",
                          "VUID-vkCmdBlitImage-dstImage-00250",
                          "VUID-vkCmdBlitImage-dstImage-00252",
                          "VUID-vkCmdBlitImage-pRegions-00217"};
constexpr BlitVuids kBlit2{
    {"vkCmdBlitImage2", "VUID-VkBlitImageInfo2-srcImage-00219", "VUID-VkBlitImageInfo2-srcImage-00220",
     "VUID-VkBlitImageInfo2-srcImageLayout-01398", "VUID-VkBlitImageInfo2-srcSubresource-01705",
     "VUID-VkBlitImageInfo2-srcSubresource-01707", nullptr, "VUID-VkBlitImageInfo2-aspectMask-00241"},
    {"vkCmdBlitImage2", "VUID-VkBlitImageInfo2-dstImage-00224", "VUID-VkBlitImageInfo2-dstImage-00225",
     "VUID-VkBlitImageInfo2-dstImageLayout-01399", "VUID-VkBlitImageInfo2-dstSubresource-01706",
     "VUID-VkBlitImageInfo2-dstSubresource-01708", nullptr, "VUID-VkBlitImageInfo2-aspectMask-00242"},
    "VUID-VkBlitImageInfo2-srcImage-00229",
    "VUID-VkBlitImageInfo2-srcImage-00230",
    "VUID-VkBlitImageInfo2-filter-02001",
    "VUID-VkBlitImageInfo2-filter-02002",
    "VUID-VkBlitImageInfo2-filter-parameter",
    "VUID-VkImageBlit2-aspectMask-00238",
    "VUID-VkImageBlit2-layerCount-00239",
    "VUID-VkBlitImageInfo2-srcImage-00240",
    "VUID-VkBlitImageInfo2-srcOffset-00243",
    "VUID-VkBlitImageInfo2-srcOffset-00244",
    "VUID-VkBlitImageInfo2-srcOffset-00246",
    "VUID-VkBlitImageInfo2-srcImage-00245",
    "VUID-VkBlitImageInfo2-srcImage-00247",
    "VUID-VkBlitImageInfo2-dstOffset-00248",
    "VUID-VkBlitImageInfo2-dstOffset-00249",
    "VUID-VkBlitImageInfo2-dstOffset-00251",
    "VUID-VkBlitImageInfo2-dstImage-00250",
    "VUID-VkBlitImageInfo2-dstImage-00252",
    "VUID-VkBlitImageInfo2-pRegions-00217"};

bool layoutOk(VkImageLayout l, bool dst) {
  return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHARED_PRESENT_KHR ||
         l == (dst ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

}  // namespace

namespace vkrt {

Image* transferImage(CommandBuffer* cb, VkImage h, bool dst, VkImageLayout layout, const Vuids& v,
                     VkImageAspectFlags aspects, const AspectUsageVuids* av) {
  Image* img = fromHandle<Image>(h);
  if (!img) {
    report(cb, Severity::Error, nullptr, "%s: %s 0x%llx is not a live VkImage", v.fn, dst ? "dstImage" : "srcImage",
           (ull)rawHandle(h));
    return nullptr;
  }
  // VUID ...-dstImage-00177 / srcImage-00186 / image-00002 / srcImage-00219 / dstImage-00224 etc.: transfer usage;
  // per aspect (vkCmdCopyImage aspect-06662..06665, vkCmdClearDepthStencilImage pRanges-02658..02660)
  const VkImageUsageFlags bit = dst ? VK_IMAGE_USAGE_TRANSFER_DST_BIT : VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  const VkImageAspectFlags stencil = VK_IMAGE_ASPECT_STENCIL_BIT;
  const bool other = !av || !aspects || (aspects & ~stencil);
  const char* vuid = nullptr;
  if (other && !(img->usage & bit))
    vuid = av && img->separateStencilUsage ? av->separateOther : v.usage;
  else if ((aspects & stencil) && !(img->stencilUsage & bit))
    vuid = !av ? v.usage : img->separateStencilUsage ? av->separateStencil : av->stencil ? av->stencil : v.usage;
  if (vuid) {
    const bool s = !(other && !(img->usage & bit));
    report(img, Severity::Error, vuid,
           "%s: %s was created without VK_IMAGE_USAGE_TRANSFER_%s_BIT (%s 0x%x, aspects 0x%x)", v.fn,
           s ? "the image's stencil aspect" : "the image", dst ? "DST" : "SRC",
           s && img->separateStencilUsage ? "stencilUsage" : "usage", s ? img->stencilUsage : img->usage, aspects);
    return nullptr;
  }
  // VUID ...-00178 / 00187 / 00127 / 00132 / 00220 / 00225 / image-00003: bound to memory
  if (!img->memory) {
    report(img, Severity::Error, v.bound, "%s: the image is not bound to memory", v.fn);
    return nullptr;
  }
  // VUID ...-dstImageLayout-01396 / srcImageLayout-01397 / 01917 / 01395 / 01398 / 01399 / imageLayout-01394
  if (!layoutOk(layout, dst)) {
    report(img, Severity::Error, v.layout, "%s: image layout %d is not GENERAL, SHARED_PRESENT or TRANSFER_%s_OPTIMAL",
           v.fn, (int)layout, dst ? "DST" : "SRC");
    return nullptr;
  }
  return img;
}

// Checks that the aspect, mip level and layers of `sub` exist in the image.
bool subresourceInImage(const Image& img, const VkImageSubresourceLayers& sub, uint32_t index, const char* what,
                        const Vuids& v) {
  // VUID ...-aspectMask-00211 / 00142 / 00143 / 00241 / 00242: aspects the image has
  if (!sub.aspectMask || (sub.aspectMask & ~img.aspects)) {
    report(&img, Severity::Error, v.aspect, "%s: pRegions[%u].%s aspectMask 0x%x is not among the image's aspects 0x%x",
           v.fn, index, what, sub.aspectMask, img.aspects);
    return false;
  }
  // VUID ...-imageSubresource-01701/01703, srcSubresource-01696/01705, dstSubresource-01697/01706: the mip exists
  if (sub.mipLevel >= img.mipLevels) {
    report(&img, Severity::Error, v.mip, "%s: pRegions[%u].%s.mipLevel %u, the image has %u", v.fn, index, what,
           sub.mipLevel, img.mipLevels);
    return false;
  }
  // VUID ...-imageSubresource-01702/01704, srcSubresource-01698/01707, dstSubresource-01699/01708: layers exist
  if (sub.layerCount == 0 || sub.baseArrayLayer >= img.arrayLayers ||
      sub.layerCount > img.arrayLayers - sub.baseArrayLayer) {
    report(&img, Severity::Error, v.layers, "%s: pRegions[%u].%s layers [%u, +%u) exceed the image's %u layers", v.fn,
           index, what, sub.baseArrayLayer, sub.layerCount, img.arrayLayers);
    return false;
  }
  return true;
}

// Checks that [offset, offset + extent) of (mip, layers) lies inside the image.
bool regionInImage(const Image& img, const VkImageSubresourceLayers& sub, VkOffset3D off, VkExtent3D ext,
                   uint32_t index, const char* what, const Vuids& v) {
  if (!subresourceInImage(img, sub, index, what, v)) return false;
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

}  // namespace vkrt

namespace {

// Of the region (`off`, `ext`, in texels) of mip `mip` of a compressed image, the first rule of the four it breaks:
// rules[0] / [1], x / y offsets multiples of the block; rules[2] / [3], width / height multiples of the block unless
// they reach the mip level's edge (the block's depth is 1: z is free); nullptr when it keeps them.
const char* misalignedBlockRule(const Image& img, uint32_t mip, VkOffset3D off, VkExtent3D ext,
                                const char* const rules[4]) {
  const uint32_t b = img.formatInfo->block;
  const VkExtent3D m = img.mips[mip].extent;
  return uint32_t(off.x) % b                                               ? rules[0]
         : uint32_t(off.y) % b                                             ? rules[1]
         : ext.width % b != 0 && uint64_t(off.x) + ext.width != m.width    ? rules[2]
         : ext.height % b != 0 && uint64_t(off.y) + ext.height != m.height ? rules[3]
                                                                           : nullptr;
}

// The rules of buffer copies of a compressed image ("Copying Data Between Buffers and Images": regions in whole 4x4
// blocks but at the mip level's edge): VUID ...-bufferRowLength-00203, bufferImageHeight-00204 (multiples of the
// block), pRegions-07274 / 07275 (offsets), imageExtent-00207 / 00208 (extents, unless they reach the edge). The
// block's depth is 1: z is free. True for uncompressed formats.
bool blockAligned(const Image& img, const VkBufferImageCopy2& r, uint32_t index, bool toImage, bool two,
                  const char* fn) {
  const uint32_t b = img.formatInfo->block;
  if (b == 1) return true;
  const VkExtent3D m = img.mips[r.imageSubresource.mipLevel].extent;
  static const char* const kRules[4] = {"pRegions-07274", "pRegions-07275", "imageExtent-00207", "imageExtent-00208"};
  const char* rule = r.bufferRowLength % b ? "bufferRowLength-00203"
                     : r.bufferImageHeight % b
                         ? "bufferImageHeight-00204"
                         : misalignedBlockRule(img, r.imageSubresource.mipLevel, r.imageOffset, r.imageExtent, kRules);
  if (!rule) return true;
  const std::string vuid = std::string("VUID-") +
                           (toImage ? (two ? "VkCopyBufferToImageInfo2-" : "vkCmdCopyBufferToImage-")
                                    : (two ? "VkCopyImageToBufferInfo2-" : "vkCmdCopyImageToBuffer-")) +
                           rule;
  report(&img, Severity::Error, vuid.c_str(),
         "%s: pRegions[%u] (bufferRowLength %u, bufferImageHeight %u, imageOffset (%d, %d, %d), imageExtent (%u, %u, "
         "%u)) of format %d: offsets, bufferRowLength and bufferImageHeight must be multiples of the %ux%u texel "
         "block, and extents too unless they reach the edge of mip %u (%u x %u)",
         fn, index, r.bufferRowLength, r.bufferImageHeight, r.imageOffset.x, r.imageOffset.y, r.imageOffset.z,
         r.imageExtent.width, r.imageExtent.height, r.imageExtent.depth, (int)img.format, b, b,
         r.imageSubresource.mipLevel, m.width, m.height);
  return false;
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
  VkImageAspectFlags aspects = 0;
  for (const VkBufferImageCopy2& r : regions) aspects |= r.imageSubresource.aspectMask;
  Image* img = transferImage(cb, imageH, toImage, layout, v, aspects);
  if (!img) return;
  const bool two = std::strchr(v.fn, '2') != nullptr;
  // VUID-vkCmdCopyBufferToImage-dstImage-07973 / vkCmdCopyImageToBuffer-srcImage-07973 (and the 2 versions):
  // single-sampled images only
  if (img->samples != 1) {
    report(img, Severity::Error,
           toImage
               ? (two ? "VUID-VkCopyBufferToImageInfo2-dstImage-07973" : "VUID-vkCmdCopyBufferToImage-dstImage-07973")
               : (two ? "VUID-VkCopyImageToBufferInfo2-srcImage-07973" : "VUID-vkCmdCopyImageToBuffer-srcImage-07973"),
           "%s: the image has %u samples; buffer copies need VK_SAMPLE_COUNT_1_BIT", v.fn, img->samples);
    return;
  }
  for (uint32_t i = 0; i < regions.size(); ++i) {
    const VkBufferImageCopy2& r = regions[i];
    if (!regionInImage(*img, r.imageSubresource, r.imageOffset, r.imageExtent, i, "imageSubresource", v)) return;
    // VUID-VkBufferImageCopy(2)-aspectMask-00212: one aspect per region
    const VkImageAspectFlags aspect = r.imageSubresource.aspectMask;
    if (aspect & (aspect - 1)) {
      report(img, Severity::Error,
             two ? "VUID-VkBufferImageCopy2-aspectMask-00212" : "VUID-VkBufferImageCopy-aspectMask-00212",
             "%s: pRegions[%u].imageSubresource.aspectMask 0x%x has more than one aspect", v.fn, i, aspect);
      return;
    }
    const uint32_t t = aspectBufferTexelSize(img->format, aspect);
    if (!blockAligned(*img, r, i, toImage, two, v.fn)) return;
    // VUID-vkCmdCopyBufferToImage-srcImage-04053 (and the 3 others): depth/stencil copies at multiples of 4 bytes
    if (aspect != VK_IMAGE_ASPECT_COLOR_BIT && r.bufferOffset % 4) {
      report(
          buf, Severity::Error,
          toImage
              ? (two ? "VUID-VkCopyBufferToImageInfo2-srcImage-04053" : "VUID-vkCmdCopyBufferToImage-srcImage-04053")
              : (two ? "VUID-VkCopyImageToBufferInfo2-srcImage-04053" : "VUID-vkCmdCopyImageToBuffer-srcImage-04053"),
          "%s: pRegions[%u].bufferOffset %llu of a depth/stencil copy is not a multiple of 4", v.fn, i,
          (ull)r.bufferOffset);
      return;
    }
    // VUID-VkBufferImageCopy(2)-bufferRowLength-00195 / bufferImageHeight-00196
    if ((r.bufferRowLength && r.bufferRowLength < r.imageExtent.width) ||
        (r.bufferImageHeight && r.bufferImageHeight < r.imageExtent.height)) {
      bool row = r.bufferRowLength && r.bufferRowLength < r.imageExtent.width;
      report(buf, Severity::Error, row ? v.rowLength : v.imageHeight,
             "%s: pRegions[%u] bufferRowLength %u / bufferImageHeight %u is smaller than the extent (%u, %u)", v.fn, i,
             r.bufferRowLength, r.bufferImageHeight, r.imageExtent.width, r.imageExtent.height);
      return;
    }
    // VUID ...-bufferOffset-00193: a multiple of the texel (block) size
    if (r.bufferOffset % t) {
      report(buf, Severity::Error, v.bufOffset,
             "%s: pRegions[%u].bufferOffset %llu is not a multiple of the %u-byte texel%s", v.fn, i,
             (ull)r.bufferOffset, t, img->formatInfo->block > 1 ? " block" : "");
      return;
    }
    // VUID ...-pRegions-00171 / 00183: the buffer holds every addressed texel (whole blocks of a compressed image)
    VkDeviceSize need = bufferFootprint(r, t, img->formatInfo->block);
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

// The destination's extent of an image copy region, in its texels: the region's extent is in the source's texels
// ("Copying Data Between Images"), one texel of an uncompressed format for one block of a compressed one (a
// compressed source's partial edge block: one texel). An uncompressed source's texel is a whole block of a
// compressed destination, which must fit the level (VUID ...-dstOffset-00150, as the validation layer checks it):
// the last, partial, blocks of a compressed level are written by buffer copies and copies between compressed images.
VkExtent3D destinationExtent(const Image& src, const Image& dst, const VkImageCopy2& r) {
  const uint32_t sb = src.formatInfo->block, db = dst.formatInfo->block;
  VkExtent3D e = r.extent;
  if (sb == db) return e;
  if (sb > 1) {
    e.width = (e.width + sb - 1) / sb;
    e.height = (e.height + sb - 1) / sb;
    return e;
  }
  e.width *= db;
  e.height *= db;
  return e;
}

// The rules of image copies of a compressed side (`ext` in that side's texels): VUID ...-pRegions-07278 / 07279
// (srcOffset) and 07281 / 07282 (dstOffset) multiples of the block, srcImage-01728 / 01729 and dstImage-01732 / 01733
// (extents multiples of the block unless they reach the mip level's edge). The block's depth is 1.
bool copyBlockAligned(const Image& img, const VkImageSubresourceLayers& sub, VkOffset3D off, VkExtent3D ext,
                      uint32_t index, bool src, bool two, const char* fn) {
  const uint32_t b = img.formatInfo->block;
  if (b == 1) return true;
  const VkExtent3D m = img.mips[sub.mipLevel].extent;
  static const char* const kSrcRules[4] = {"pRegions-07278", "pRegions-07279", "srcImage-01728", "srcImage-01729"};
  static const char* const kDstRules[4] = {"pRegions-07281", "pRegions-07282", "dstImage-01732", "dstImage-01733"};
  const char* rule = misalignedBlockRule(img, sub.mipLevel, off, ext, src ? kSrcRules : kDstRules);
  if (!rule) return true;
  const std::string vuid = std::string(two ? "VUID-VkCopyImageInfo2-" : "VUID-vkCmdCopyImage-") + rule;
  report(&img, Severity::Error, vuid.c_str(),
         "%s: pRegions[%u] %s offset (%d, %d, %d) extent (%u, %u, %u) of format %d: offsets must be multiples of the "
         "%ux%u texel block, and extents too unless they reach the edge of mip %u (%u x %u)",
         fn, index, src ? "source" : "destination", off.x, off.y, off.z, ext.width, ext.height, ext.depth,
         (int)img.format, b, b, sub.mipLevel, m.width, m.height);
  return false;
}

void recordImageCopy(CommandBuffer* cb, VkImage srcH, VkImageLayout srcLayout, VkImage dstH, VkImageLayout dstLayout,
                     std::vector<VkImageCopy2> regions, const Vuids& vs, const Vuids& vd, const char* sizeVuid,
                     const char* layerVuid) {
  const bool two = std::strchr(vs.fn, '2') != nullptr;
  // VUID-vkCmdCopyImage-aspect-06662 / 06663 / 06664 / 06665 (separate stencil usage); 00126 / 00131 otherwise
  static constexpr AspectUsageVuids kSrc{nullptr, "VUID-vkCmdCopyImage-aspect-06664",
                                         "VUID-vkCmdCopyImage-aspect-06662"};
  static constexpr AspectUsageVuids kDst{nullptr, "VUID-vkCmdCopyImage-aspect-06665",
                                         "VUID-vkCmdCopyImage-aspect-06663"};
  static constexpr AspectUsageVuids kSrc2{nullptr, "VUID-VkCopyImageInfo2-aspect-06664",
                                          "VUID-VkCopyImageInfo2-aspect-06662"};
  static constexpr AspectUsageVuids kDst2{nullptr, "VUID-VkCopyImageInfo2-aspect-06665",
                                          "VUID-VkCopyImageInfo2-aspect-06663"};
  VkImageAspectFlags srcAspects = 0, dstAspects = 0;
  for (const VkImageCopy2& r : regions) {
    srcAspects |= r.srcSubresource.aspectMask;
    dstAspects |= r.dstSubresource.aspectMask;
  }
  Image* src = transferImage(cb, srcH, false, srcLayout, vs, srcAspects, two ? &kSrc2 : &kSrc);
  Image* dst = src ? transferImage(cb, dstH, true, dstLayout, vd, dstAspects, two ? &kDst2 : &kDst) : nullptr;
  if (!src || !dst) return;
  // VUID-vkCmdCopyImage-srcImage-01548: size-compatible formats (same texel size for vkrt's formats)
  if (src->formatInfo->texelSize != dst->formatInfo->texelSize) {
    report(dst, Severity::Error, sizeVuid, "%s: formats %d and %d have different texel sizes (%u, %u)", vs.fn,
           (int)src->format, (int)dst->format, src->formatInfo->texelSize, dst->formatInfo->texelSize);
    return;
  }
  // VUID-vkCmdCopyImage-srcImage-01548 for depth/stencil formats: identical formats ("Format Compatibility
  // Classes": each depth/stencil format is its own class)
  if ((isDepthStencilFormat(src->format) || isDepthStencilFormat(dst->format)) && src->format != dst->format) {
    report(dst, Severity::Error, sizeVuid, "%s: depth/stencil formats %d and %d differ", vs.fn, (int)src->format,
           (int)dst->format);
    return;
  }
  // VUID-vkCmdCopyImage-sampleCount-00136: the same sample count
  if (src->samples != dst->samples) {
    report(dst, Severity::Error,
           two ? "VUID-VkCopyImageInfo2-sampleCount-00136" : "VUID-vkCmdCopyImage-sampleCount-00136",
           "%s: srcImage has %u samples, dstImage %u", vs.fn, src->samples, dst->samples);
    return;
  }
  for (uint32_t i = 0; i < regions.size(); ++i) {
    VkImageCopy2& r = regions[i];
    // VUID-VkImageCopy-aspectMask-00137: the same aspects on both sides
    if (r.srcSubresource.aspectMask != r.dstSubresource.aspectMask) {
      report(dst, Severity::Error, two ? "VUID-VkImageCopy2-aspectMask-00137" : "VUID-VkImageCopy-aspectMask-00137",
             "%s: pRegions[%u] copies aspects 0x%x into aspects 0x%x", vs.fn, i, r.srcSubresource.aspectMask,
             r.dstSubresource.aspectMask);
      return;
    }
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
    VkExtent3D srcExt = r.extent, dstExt = destinationExtent(*src, *dst, r);
    if (src->type != VK_IMAGE_TYPE_3D && dst->type == VK_IMAGE_TYPE_3D) srcExt.depth = 1;
    if (src->type == VK_IMAGE_TYPE_3D && dst->type != VK_IMAGE_TYPE_3D) dstExt.depth = 1;
    if (!regionInImage(*src, r.srcSubresource, r.srcOffset, srcExt, i, "srcSubresource", vs) ||
        !regionInImage(*dst, r.dstSubresource, r.dstOffset, dstExt, i, "dstSubresource", vd))
      return;
    if (!copyBlockAligned(*src, r.srcSubresource, r.srcOffset, srcExt, i, true, two, vs.fn) ||
        !copyBlockAligned(*dst, r.dstSubresource, r.dstOffset, dstExt, i, false, two, vs.fn))
      return;
  }
  cb->record([src, dst, regions = std::move(regions)](ExecState&) {
    for (const VkImageCopy2& r : regions) copyImageImage(*src, *dst, r);
  });
}

// The box [lo, hi) a blit region's offsets span in each dimension (either offset may be the larger).
struct Box {
  int32_t lo[3], hi[3];
  explicit Box(const VkOffset3D o[2]) {
    const int32_t a[3] = {o[0].x, o[0].y, o[0].z}, b[3] = {o[1].x, o[1].y, o[1].z};
    for (int d = 0; d < 3; ++d) lo[d] = std::min(a[d], b[d]), hi[d] = std::max(a[d], b[d]);
  }
  bool intersects(const Box& o) const {
    for (int d = 0; d < 3; ++d)
      if (std::max(lo[d], o.lo[d]) >= std::min(hi[d], o.hi[d])) return false;
    return true;
  }
};

// Checks one side's offsets of blit region `index` against mip `sub.mipLevel` of the image (the subresource was
// checked first). `src`: which side, for the VUIDs and the message.
bool blitOffsetsInImage(const Image& img, const VkImageSubresourceLayers& sub, const VkOffset3D o[2], uint32_t index,
                        bool src, const BlitVuids& v) {
  const char* fn = v.src.fn;
  const char* what = src ? "srcOffsets" : "dstOffsets";
  const VkExtent3D m = img.mips[sub.mipLevel].extent;
  auto inside = [](int32_t a, int32_t b, uint32_t size) {
    return a >= 0 && b >= 0 && a <= int64_t(size) && b <= int64_t(size);
  };
  const char* vuid = nullptr;
  // VUID ...-srcOffset-00243 / dstOffset-00248: x in [0, width]
  if (!inside(o[0].x, o[1].x, m.width)) vuid = src ? v.srcX : v.dstX;
  // VUID ...-srcImage-00245 / dstImage-00250: a 1D image's y offsets are 0 and 1; else
  // VUID ...-srcOffset-00244 / dstOffset-00249: y in [0, height]
  else if (img.type == VK_IMAGE_TYPE_1D && (o[0].y != 0 || o[1].y != 1))
    vuid = src ? v.src1D : v.dst1D;
  else if (!inside(o[0].y, o[1].y, m.height))
    vuid = src ? v.srcY : v.dstY;
  // VUID ...-srcImage-00247 / dstImage-00252: a 1D or 2D image's z offsets are 0 and 1; else
  // VUID ...-srcOffset-00246 / dstOffset-00251: z in [0, depth]
  else if (img.type != VK_IMAGE_TYPE_3D && (o[0].z != 0 || o[1].z != 1))
    vuid = src ? v.src2D : v.dst2D;
  else if (!inside(o[0].z, o[1].z, m.depth))
    vuid = src ? v.srcZ : v.dstZ;
  if (!vuid) return true;
  report(&img, Severity::Error, vuid,
         "%s: pRegions[%u].%s (%d, %d, %d) and (%d, %d, %d) are outside mip %u (%u x %u x %u) of the %uD image", fn,
         index, what, o[0].x, o[0].y, o[0].z, o[1].x, o[1].y, o[1].z, sub.mipLevel, m.width, m.height, m.depth,
         img.type == VK_IMAGE_TYPE_1D   ? 1u
         : img.type == VK_IMAGE_TYPE_2D ? 2u
                                        : 3u);
  return false;
}

const char* numericName(NumericType t) {
  switch (t) {
    case NumericType::UNorm: return "UNORM";
    case NumericType::SNorm: return "SNORM";
    case NumericType::UInt: return "UINT";
    case NumericType::SInt: return "SINT";
    case NumericType::SFloat: return "SFLOAT";
    case NumericType::SRGB: return "SRGB";
    case NumericType::UFloat: return "UFLOAT";
  }
  return "?";
}

void recordBlit(CommandBuffer* cb, VkImage srcH, VkImageLayout srcLayout, VkImage dstH, VkImageLayout dstLayout,
                std::vector<VkImageBlit2> regions, VkFilter filter, const BlitVuids& v) {
  const char* fn = v.src.fn;
  Image* src = transferImage(cb, srcH, false, srcLayout, v.src);
  Image* dst = src ? transferImage(cb, dstH, true, dstLayout, v.dst) : nullptr;
  if (!src || !dst) return;
  const VkFormatFeatureFlags srcFeatures = formatFeatures(src->format);
  const bool two = std::strchr(fn, '2') != nullptr;
  // VUID ...-srcImage-01999 / dstImage-02000: BLIT_SRC / BLIT_DST format features (every color format has both;
  // depth/stencil formats have no BLIT_DST: runtime/format.cpp)
  const bool srcOk = srcFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT;
  if (!srcOk || !(formatFeatures(dst->format) & VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
    report(srcOk ? dst : src, Severity::Error,
           srcOk ? (two ? "VUID-VkBlitImageInfo2-dstImage-02000" : "VUID-vkCmdBlitImage-dstImage-02000")
                 : (two ? "VUID-VkBlitImageInfo2-srcImage-01999" : "VUID-vkCmdBlitImage-srcImage-01999"),
           "%s: format %d lacks VK_FORMAT_FEATURE_BLIT_%s_BIT", fn, (int)(srcOk ? dst : src)->format,
           srcOk ? "DST" : "SRC");
    return;
  }
  // VUID ...-srcImage-00233 / dstImage-00234: single-sampled images
  if (src->samples != 1 || dst->samples != 1) {
    const bool s = src->samples != 1;
    report(s ? src : dst, Severity::Error,
           s ? (two ? "VUID-VkBlitImageInfo2-srcImage-00233" : "VUID-vkCmdBlitImage-srcImage-00233")
             : (two ? "VUID-VkBlitImageInfo2-dstImage-00234" : "VUID-vkCmdBlitImage-dstImage-00234"),
           "%s: %s has %u samples; blits need VK_SAMPLE_COUNT_1_BIT", fn, s ? "srcImage" : "dstImage",
           s ? src->samples : dst->samples);
    return;
  }
  // VUID ...-srcImage-00229 / 00230: integer formats blit only to and from integers of the same signedness
  // ("Integer formats can only be converted to other integer formats with the same signedness")
  const NumericType st = src->formatInfo->type, dt = dst->formatInfo->type;
  const bool sint = st == NumericType::SInt || dt == NumericType::SInt;
  const bool uint = st == NumericType::UInt || dt == NumericType::UInt;
  if ((sint && st != dt) || (uint && st != dt)) {
    report(dst, Severity::Error, sint ? v.sint : v.uint,
           "%s: source format %d (%s) and destination format %d (%s): %s integer format blits only to and from "
           "%s integer formats",
           fn, (int)src->format, numericName(st), (int)dst->format, numericName(dt), sint ? "a signed" : "an unsigned",
           sint ? "signed" : "unsigned");
    return;
  }
  // VUID ...-filter-parameter / filter-02001 / filter-02002
  if (filter != VK_FILTER_NEAREST && filter != VK_FILTER_LINEAR) {
    report(src, Severity::Error, filter == VK_FILTER_CUBIC_EXT ? v.cubic : v.filter,
           "%s: filter %d is not VK_FILTER_NEAREST or VK_FILTER_LINEAR (vkrt offers no cubic filtering)", fn,
           (int)filter);
    return;
  }
  if (filter == VK_FILTER_LINEAR && !(srcFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
    report(src, Severity::Error, v.linear,
           "%s: VK_FILTER_LINEAR, but source format %d (%s) lacks VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT",
           fn, (int)src->format, numericName(st));
    return;
  }
  const bool any3D = src->type == VK_IMAGE_TYPE_3D || dst->type == VK_IMAGE_TYPE_3D;
  for (uint32_t i = 0; i < regions.size(); ++i) {
    const VkImageBlit2& r = regions[i];
    // VUID-VkImageBlit(2)-aspectMask-00238 / layerCount-00239
    if (r.srcSubresource.aspectMask != r.dstSubresource.aspectMask ||
        r.srcSubresource.layerCount != r.dstSubresource.layerCount) {
      const bool aspects = r.srcSubresource.aspectMask != r.dstSubresource.aspectMask;
      report(dst, Severity::Error, aspects ? v.aspects : v.layerCounts,
             "%s: pRegions[%u] blits aspects 0x%x x %u layers into aspects 0x%x x %u layers", fn, i,
             r.srcSubresource.aspectMask, r.srcSubresource.layerCount, r.dstSubresource.aspectMask,
             r.dstSubresource.layerCount);
      return;
    }
    if (!subresourceInImage(*src, r.srcSubresource, i, "srcSubresource", v.src) ||
        !subresourceInImage(*dst, r.dstSubresource, i, "dstSubresource", v.dst))
      return;
    // VUID ...-srcImage-00240: with a 3D image on either side, both sides are layer 0 alone
    if (any3D && (r.srcSubresource.baseArrayLayer != 0 || r.srcSubresource.layerCount != 1 ||
                  r.dstSubresource.baseArrayLayer != 0 || r.dstSubresource.layerCount != 1)) {
      report(dst, Severity::Error, v.threeD,
             "%s: pRegions[%u] blits layers [%u, +%u) into [%u, +%u), but with a 3D image both must be layer 0 alone",
             fn, i, r.srcSubresource.baseArrayLayer, r.srcSubresource.layerCount, r.dstSubresource.baseArrayLayer,
             r.dstSubresource.layerCount);
      return;
    }
    if (!blitOffsetsInImage(*src, r.srcSubresource, r.srcOffsets, i, true, v) ||
        !blitOffsetsInImage(*dst, r.dstSubresource, r.dstOffsets, i, false, v))
      return;
  }
  // VUID ...-pRegions-00217: no destination region may overlap "any texel that may be sampled", in the same mip and
  // layer of the same image. vkrt checks the source regions themselves, which are sampled whatever the rounding;
  // the texels just outside one that a LINEAR filter may read (with weight 0 at a 1:1 scale) are left unchecked
  // so that no valid blit is ever reported.
  if (src == dst) {
    for (uint32_t d = 0; d < regions.size(); ++d)
      for (uint32_t s = 0; s < regions.size(); ++s) {
        const VkImageSubresourceLayers &ds = regions[d].dstSubresource, &ss = regions[s].srcSubresource;
        const bool sameLayers = ds.baseArrayLayer < ss.baseArrayLayer + ss.layerCount &&
                                ss.baseArrayLayer < ds.baseArrayLayer + ds.layerCount;
        if (ds.mipLevel != ss.mipLevel || !sameLayers ||
            !Box(regions[d].dstOffsets).intersects(Box(regions[s].srcOffsets)))
          continue;
        report(dst, Severity::Error, v.overlap,
               "%s: pRegions[%u]'s destination region overlaps pRegions[%u]'s source region (mip %u of the same image)",
               fn, d, s, ds.mipLevel);
        return;
      }
  }
  cb->record([src, dst, regions = std::move(regions), filter](ExecState&) {
    blitImage(*src, *dst, regions.data(), uint32_t(regions.size()), filter);
  });
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBufferToImage(VkCommandBuffer commandBuffer, VkBuffer srcBuffer,
                                                     VkImage dstImage, VkImageLayout dstImageLayout,
                                                     uint32_t regionCount, const VkBufferImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBufferToImage");
  if (!cb) return;
  // VUID-vkCmdCopyBufferToImage-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyBufferToImage", "VUID-vkCmdCopyBufferToImage-renderpass")) return;
  std::vector<VkBufferImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toCopy2(pRegions[i]));
  recordBufferImage(cb, srcBuffer, dstImage, dstImageLayout, std::move(regions), true, kBufferToImage);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyBufferToImage2(VkCommandBuffer commandBuffer,
                                                      const VkCopyBufferToImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyBufferToImage2");
  if (!cb) return;
  // VUID-vkCmdCopyBufferToImage2-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyBufferToImage2", "VUID-vkCmdCopyBufferToImage2-renderpass")) return;
  std::vector<VkBufferImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBufferImage(cb, pInfo->srcBuffer, pInfo->dstImage, pInfo->dstImageLayout, std::move(regions), true,
                    kBufferToImage2);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer(VkCommandBuffer commandBuffer, VkImage srcImage,
                                                     VkImageLayout srcImageLayout, VkBuffer dstBuffer,
                                                     uint32_t regionCount, const VkBufferImageCopy* pRegions) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer");
  if (!cb) return;
  // VUID-vkCmdCopyImageToBuffer-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyImageToBuffer", "VUID-vkCmdCopyImageToBuffer-renderpass")) return;
  std::vector<VkBufferImageCopy2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) regions.push_back(toCopy2(pRegions[i]));
  recordBufferImage(cb, dstBuffer, srcImage, srcImageLayout, std::move(regions), false, kImageToBuffer);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyImageToBuffer2(VkCommandBuffer commandBuffer,
                                                      const VkCopyImageToBufferInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdCopyImageToBuffer2");
  if (!cb) return;
  // VUID-vkCmdCopyImageToBuffer2-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyImageToBuffer2", "VUID-vkCmdCopyImageToBuffer2-renderpass")) return;
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
  // VUID-vkCmdCopyImage-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyImage", "VUID-vkCmdCopyImage-renderpass")) return;
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
  // VUID-vkCmdCopyImage2-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdCopyImage2", "VUID-vkCmdCopyImage2-renderpass")) return;
  std::vector<VkImageCopy2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordImageCopy(cb, pInfo->srcImage, pInfo->srcImageLayout, pInfo->dstImage, pInfo->dstImageLayout,
                  std::move(regions), kCopySrc2, kCopyDst2, "VUID-VkCopyImageInfo2-srcImage-01548",
                  "VUID-VkCopyImageInfo2-srcImage-07744");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBlitImage(VkCommandBuffer commandBuffer, VkImage srcImage,
                                             VkImageLayout srcImageLayout, VkImage dstImage,
                                             VkImageLayout dstImageLayout, uint32_t regionCount,
                                             const VkImageBlit* pRegions, VkFilter filter) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBlitImage");
  if (!cb) return;
  // VUID-vkCmdBlitImage-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdBlitImage", "VUID-vkCmdBlitImage-renderpass")) return;
  std::vector<VkImageBlit2> regions;
  for (uint32_t i = 0; i < regionCount; ++i) {
    const VkImageBlit& r = pRegions[i];
    regions.push_back({VK_STRUCTURE_TYPE_IMAGE_BLIT_2,
                       nullptr,
                       r.srcSubresource,
                       {r.srcOffsets[0], r.srcOffsets[1]},
                       r.dstSubresource,
                       {r.dstOffsets[0], r.dstOffsets[1]}});
  }
  recordBlit(cb, srcImage, srcImageLayout, dstImage, dstImageLayout, std::move(regions), filter, kBlit);
}

// Also vkCmdBlitImage2KHR (VK_KHR_copy_commands2), an alias.
VKAPI_ATTR void VKAPI_CALL vkrt_CmdBlitImage2(VkCommandBuffer commandBuffer, const VkBlitImageInfo2* pInfo) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBlitImage2");
  if (!cb) return;
  // VUID-vkCmdBlitImage2-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdBlitImage2", "VUID-vkCmdBlitImage2-renderpass")) return;
  std::vector<VkImageBlit2> regions(pInfo->pRegions, pInfo->pRegions + pInfo->regionCount);
  recordBlit(cb, pInfo->srcImage, pInfo->srcImageLayout, pInfo->dstImage, pInfo->dstImageLayout, std::move(regions),
             pInfo->filter, kBlit2);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdClearColorImage(VkCommandBuffer commandBuffer, VkImage image,
                                                   VkImageLayout imageLayout, const VkClearColorValue* pColor,
                                                   uint32_t rangeCount, const VkImageSubresourceRange* pRanges) {
  const char* fn = "vkCmdClearColorImage";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdClearColorImage-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdClearColorImage-renderpass")) return;
  Image* img = transferImage(cb, image, true, imageLayout, kClear);
  if (!img) return;
  // VUID-vkCmdClearColorImage-image-00007: not a compressed or depth/stencil format
  if (img->aspects != VK_IMAGE_ASPECT_COLOR_BIT || img->formatInfo->block > 1) {
    report(img, Severity::Error, "VUID-vkCmdClearColorImage-image-00007", "%s: the image's format %d is a %s format",
           fn, (int)img->format, img->formatInfo->block > 1 ? "compressed" : "depth/stencil");
    return;
  }
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

}  // extern "C"
