// vkCmdBlitImage and vkCmdBlitImage2 (and its VK_KHR_copy_commands2 alias) through the loader: mip chains built by
// halving, up- and downscaling with NEAREST and LINEAR, mirrored regions, format conversion (UNORM, SNORM, SRGB,
// SFLOAT, and integer clamping), 1D, 3D, layers and mips, the format features that advertise blits, and misuse
// by VUID. Every expectation is computed here from the spec's formulas ("Image Copies With Scaling", "Texel
// Filtering", the sRGB transfer functions), never with vkrt's code.
//
// vkCmdBlitImage is a graphics command (VUID-vkCmdBlitImage-commandBuffer-cmdpool): vkrt's queue family has
// VK_QUEUE_GRAPHICS_BIT, so the validation layer reports nothing about it (acceptBlitQueueReports checks that).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "e2e/image_fixture.hpp"

namespace vkrt::test {
namespace {

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }
double linearToSrgb(double l) {
  l = std::clamp(l, 0.0, 1.0);
  return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

float halfToFloat(uint16_t h) {
  const int exp = (h >> 10) & 31, man = h & 1023;
  const double v = exp == 0 ? std::ldexp(man, -24) : std::ldexp(man | 1024, exp - 25);  // no Inf/NaN used here
  return float(h & 0x8000 ? -v : v);
}

// An 8-bit normalized result whose exact value is `want` (in steps of 1/255): the correctly rounded value, or at a
// tie (within float error of x.5) either neighbour.
::testing::AssertionResult nearUnorm8(int got, double want) {
  if (std::fabs(got - want) <= 0.5 + 1e-3) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got " << got << ", want " << want;
}

// The spec's linear filter along one dimension at unnormalized coordinate u over `size` texels, clamp to edge:
// texels i0 = floor(u - 1/2) and i0 + 1 with weights 1 - a and a.
struct Taps {
  int i[2];
  double w[2];
};
Taps linearTaps(double u, int size) {
  const double f = u - 0.5;
  const int i0 = int(std::floor(f));
  const double a = f - std::floor(f);
  return {{std::clamp(i0, 0, size - 1), std::clamp(i0 + 1, 0, size - 1)}, {1 - a, a}};
}

class BlitTest : public ImageTest {
 protected:
  bool graphicsQueue() {
    uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, families.data());
    return (families[0].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0;
  }

  // Checks that the layer reported no blit as recorded on a queue family without graphics (family 0 has graphics on
  // vkrt); on a driver without it, accepts one report per blit. Debian's layer (1.3.239) delivers each message to
  // both of the fixture's messengers, so a report may arrive twice.
  void acceptBlitQueueReports(size_t blits, size_t blits2 = 0) {
    const bool expected = validationEnabled && !graphicsQueue();
    auto check = [](size_t got, size_t want) {
      EXPECT_TRUE(got == want || got == 2 * want) << got << " reports for " << want << " blits";
    };
    check(takeLayerMessages("VUID-vkCmdBlitImage-commandBuffer-cmdpool"), expected ? blits : 0);
    check(takeLayerMessages("VUID-vkCmdBlitImage2-commandBuffer-cmdpool"), expected ? blits2 : 0);
  }

  static VkBufferImageCopy bufferRegion(VkDeviceSize offset, uint32_t mip, uint32_t baseLayer, uint32_t layers,
                                        VkExtent3D e) {
    VkBufferImageCopy r{};
    r.bufferOffset = offset;
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, baseLayer, layers};
    r.imageExtent = e;
    return r;
  }

  static VkImageBlit blit(uint32_t srcMip, uint32_t srcLayer, VkOffset3D s0, VkOffset3D s1, uint32_t dstMip,
                          uint32_t dstLayer, VkOffset3D d0, VkOffset3D d1, uint32_t layers = 1) {
    VkImageBlit b{};
    b.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, srcMip, srcLayer, layers};
    b.srcOffsets[0] = s0;
    b.srcOffsets[1] = s1;
    b.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, dstMip, dstLayer, layers};
    b.dstOffsets[0] = d0;
    b.dstOffsets[1] = d1;
    return b;
  }

  // Orders the transfers before it before those after it (images stay in their layout).
  static void sync(VkCommandBuffer cb) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b, 0, nullptr, 0,
                         nullptr);
  }
  static void toGeneral(VkCommandBuffer cb, VkImage image) {
    transition(cb, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  }

  // Uploads `data` into the whole of every layer of mip 0 of a new GENERAL image, blits with `record` (given the
  // source, the destination and the command buffer), and returns the destination's `mip`, all layers, read back.
  struct Pair {
    Img src, dst;
  };
  std::vector<uint8_t> blitAndRead(const VkImageCreateInfo& srcInfo, const std::vector<uint8_t>& data,
                                   const VkImageCreateInfo& dstInfo, uint32_t dstMip, size_t dstTexelSize,
                                   const std::function<void(VkCommandBuffer, VkImage, VkImage)>& record) {
    Img src = createImage(srcInfo), dst = createImage(dstInfo);
    const VkExtent3D de{std::max(1u, dstInfo.extent.width >> dstMip), std::max(1u, dstInfo.extent.height >> dstMip),
                        std::max(1u, dstInfo.extent.depth >> dstMip)};
    const size_t outSize = size_t(de.width) * de.height * de.depth * dstInfo.arrayLayers * dstTexelSize;
    HostBuffer in = createHostBuffer(data.size(), kXfer), out = createHostBuffer(outSize, kXfer);
    std::memcpy(in.data, data.data(), data.size());
    std::memset(out.data, 0xee, outSize);
    VkCommandBuffer cb = beginOneTime();
    toGeneral(cb, src.image);
    toGeneral(cb, dst.image);
    VkClearColorValue zero{};
    VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdClearColorImage(cb, dst.image, VK_IMAGE_LAYOUT_GENERAL, &zero, 1, &all);
    VkBufferImageCopy up = bufferRegion(0, 0, 0, srcInfo.arrayLayers, srcInfo.extent);
    vkCmdCopyBufferToImage(cb, in.buffer, src.image, VK_IMAGE_LAYOUT_GENERAL, 1, &up);
    sync(cb);
    record(cb, src.image, dst.image);
    sync(cb);
    VkBufferImageCopy down = bufferRegion(0, dstMip, 0, dstInfo.arrayLayers, de);
    vkCmdCopyImageToBuffer(cb, dst.image, VK_IMAGE_LAYOUT_GENERAL, out.buffer, 1, &down);
    submitAndWait(cb);
    std::vector<uint8_t> result(bytes(out), bytes(out) + outSize);
    destroy(in);
    destroy(out);
    destroy(src);
    destroy(dst);
    return result;
  }

  // A 1:1 NEAREST blit of the whole of a 2D `e` image of format `from` holding `data` to one of format `to`: the
  // destination's bytes (dstTexel per texel).
  std::vector<uint8_t> blitFormats(VkExtent3D e, VkFormat from, const std::vector<uint8_t>& data, VkFormat to,
                                   size_t dstTexel) {
    const VkOffset3D end{int32_t(e.width), int32_t(e.height), 1};
    std::vector<uint8_t> got = blitAndRead(
        imageInfo(VK_IMAGE_TYPE_2D, from, e, 1, 1), data, imageInfo(VK_IMAGE_TYPE_2D, to, e, 1, 1), 0, dstTexel,
        [&](VkCommandBuffer cb, VkImage s, VkImage d) {
          VkImageBlit r = blit(0, 0, {0, 0, 0}, end, 0, 0, {0, 0, 0}, end);
          vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_NEAREST);
        });
    acceptBlitQueueReports(1);
    return got;
  }
};

VkExtent3D mipExtent(VkExtent3D e, uint32_t mip) {
  return {std::max(1u, e.width >> mip), std::max(1u, e.height >> mip), std::max(1u, e.depth >> mip)};
}

uint8_t pattern8(uint32_t x, uint32_t y, uint32_t layer, uint32_t c) {
  return uint8_t((x * 37 + y * 11 + layer * 101 + c * 53 + x * y * 7) & 0xff);
}

TEST_F(BlitTest, FormatFeaturesAdvertiseBlitsAndLinearFiltering) {
  // "Required Format Support" (Vulkan 1.3, the 8-, 16-, 32-bit, packed and 64-bit tables): BLIT_SRC for each of
  // these, BLIT_DST for those that are also colour attachments, SAMPLED_IMAGE_FILTER_LINEAR where marked.
  struct Required {
    VkFormat format;
    bool blitDst, linear;
  };
  const Required required[] = {
      {VK_FORMAT_R8_UNORM, true, true},
      {VK_FORMAT_R8_SNORM, false, true},
      {VK_FORMAT_R8_UINT, true, false},
      {VK_FORMAT_R8_SINT, true, false},
      {VK_FORMAT_R8G8_UNORM, true, true},
      {VK_FORMAT_R8G8_SNORM, false, true},
      {VK_FORMAT_R8G8_UINT, true, false},
      {VK_FORMAT_R8G8_SINT, true, false},
      {VK_FORMAT_R8G8B8A8_UNORM, true, true},
      {VK_FORMAT_R8G8B8A8_SNORM, false, true},
      {VK_FORMAT_R8G8B8A8_UINT, true, false},
      {VK_FORMAT_R8G8B8A8_SINT, true, false},
      {VK_FORMAT_R8G8B8A8_SRGB, true, true},
      {VK_FORMAT_B8G8R8A8_UNORM, true, true},
      {VK_FORMAT_B8G8R8A8_SRGB, true, true},
      {VK_FORMAT_A2B10G10R10_UNORM_PACK32, true, true},
      {VK_FORMAT_A2B10G10R10_UINT_PACK32, true, false},
      {VK_FORMAT_R16_UINT, true, false},
      {VK_FORMAT_R16_SINT, true, false},
      {VK_FORMAT_R16_SFLOAT, true, true},
      {VK_FORMAT_R16G16_UINT, true, false},
      {VK_FORMAT_R16G16_SINT, true, false},
      {VK_FORMAT_R16G16_SFLOAT, true, true},
      {VK_FORMAT_R16G16B16A16_UINT, true, false},
      {VK_FORMAT_R16G16B16A16_SINT, true, false},
      {VK_FORMAT_R16G16B16A16_SFLOAT, true, true},
      {VK_FORMAT_R32_UINT, true, false},
      {VK_FORMAT_R32_SINT, true, false},
      {VK_FORMAT_R32_SFLOAT, true, false},
      {VK_FORMAT_R32G32_UINT, true, false},
      {VK_FORMAT_R32G32_SINT, true, false},
      {VK_FORMAT_R32G32_SFLOAT, true, false},
      {VK_FORMAT_R32G32B32A32_UINT, true, false},
      {VK_FORMAT_R32G32B32A32_SINT, true, false},
      {VK_FORMAT_R32G32B32A32_SFLOAT, true, false},
      {VK_FORMAT_B10G11R11_UFLOAT_PACK32, false, true},
      {VK_FORMAT_B4G4R4A4_UNORM_PACK16, false, true},
      {VK_FORMAT_R5G6B5_UNORM_PACK16, true, true},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, true, true},
      {VK_FORMAT_A8B8G8R8_UNORM_PACK32, true, true},
      {VK_FORMAT_A8B8G8R8_SNORM_PACK32, false, true},
      {VK_FORMAT_A8B8G8R8_UINT_PACK32, true, false},
      {VK_FORMAT_A8B8G8R8_SINT_PACK32, true, false},
      {VK_FORMAT_A8B8G8R8_SRGB_PACK32, true, true},
      {VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, false, true},
  };
  for (const Required& r : required) {
    SCOPED_TRACE(r.format);
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(physicalDevice, r.format, &p);
    EXPECT_TRUE(p.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_SRC_BIT);
    if (r.blitDst) {
      EXPECT_TRUE(p.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT);
    }
    if (r.linear) {
      EXPECT_TRUE(p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);
    }
  }
  // The two queries agree on every core format, and on vkrt every color format that makes images blits both ways
  // (depth/stencil formats: BLIT_SRC for D16 and D32 only, as required, never BLIT_DST; FormatsTest checks them),
  // but the compressed ones, blit sources only (nothing encodes a block; CompressedFormatTest).
  for (int f = VK_FORMAT_UNDEFINED; f <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK; ++f) {
    SCOPED_TRACE(f);
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(physicalDevice, VkFormat(f), &p);
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 p2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(physicalDevice, VkFormat(f), &p2);
    EXPECT_EQ(p2.formatProperties.optimalTilingFeatures, p.optimalTilingFeatures);
    EXPECT_EQ(p2.formatProperties.linearTilingFeatures, p.linearTilingFeatures);
    // (VkFormatFeatureFlags2's bits 0-30 are VkFormatFeatureFlagBits'; bit 31 and up exist only there, e.g.
    // STORAGE_READ_WITHOUT_FORMAT is bit 31.)
    constexpr VkFormatFeatureFlags2 kLegacyBits = 0x7fffffffull;
    EXPECT_EQ(p3.optimalTilingFeatures & kLegacyBits, p.optimalTilingFeatures);
    EXPECT_EQ(p3.linearTilingFeatures & kLegacyBits, p.linearTilingFeatures);
    EXPECT_EQ(p3.bufferFeatures & kLegacyBits, p.bufferFeatures);
    const bool compressed = f >= VK_FORMAT_BC1_RGB_UNORM_BLOCK && f <= VK_FORMAT_ASTC_12x12_SRGB_BLOCK;
    if (onVkrt() && (p.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) &&
        !(p.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)) {
      EXPECT_EQ(p.optimalTilingFeatures & (VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT),
                compressed ? VkFormatFeatureFlags(VK_FORMAT_FEATURE_BLIT_SRC_BIT)
                           : VkFormatFeatureFlags(VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT));
    }
  }
}

TEST_F(BlitTest, MipChainBuiltByHalvingWithLinearIsATwoByTwoAverage) {
  // The usual mipmap loop: each level blitted from the one above with VK_FILTER_LINEAR, the source level moved to
  // TRANSFER_SRC_OPTIMAL first. A halving blit samples destination texel i at source u = 2i + 1, the shared edge of
  // texels 2i and 2i + 1, so LINEAR averages them with weights 1/2 (a level of height 1 keeps its one row).
  const VkExtent3D e{16, 8, 1};
  const uint32_t mips = 5, layers = 2;  // 16x8, 8x4, 4x2, 2x1, 1x1
  Img img = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, e, mips, layers));
  std::vector<VkDeviceSize> offsets;
  VkDeviceSize total = 0;
  for (uint32_t m = 0; m < mips; ++m) {
    offsets.push_back(total);
    total += VkDeviceSize(std::max(1u, e.width >> m)) * std::max(1u, e.height >> m) * layers * 4;
  }
  HostBuffer in = createHostBuffer(total, kXfer), out = createHostBuffer(total, kXfer);
  for (uint32_t l = 0; l < layers; ++l)
    for (uint32_t y = 0; y < e.height; ++y)
      for (uint32_t x = 0; x < e.width; ++x)
        for (uint32_t c = 0; c < 4; ++c) bytes(in)[((l * e.height + y) * e.width + x) * 4 + c] = pattern8(x, y, l, c);

  auto barrier = [](VkCommandBuffer cb, VkImage image, uint32_t mip, VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 1, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                         1, &b);
  };
  VkCommandBuffer cb = beginOneTime();
  toDst(cb, img.image);
  VkBufferImageCopy up = bufferRegion(0, 0, 0, layers, e);
  vkCmdCopyBufferToImage(cb, in.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &up);
  for (uint32_t m = 1; m < mips; ++m) {
    barrier(cb, img.image, m - 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    const VkExtent3D a = mipExtent(e, m - 1), b = mipExtent(e, m);
    VkImageBlit r = blit(m - 1, 0, {0, 0, 0}, {int32_t(a.width), int32_t(a.height), 1}, m, 0, {0, 0, 0},
                         {int32_t(b.width), int32_t(b.height), 1}, layers);
    vkCmdBlitImage(cb, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                   1, &r, VK_FILTER_LINEAR);
  }
  barrier(cb, img.image, mips - 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  std::vector<VkBufferImageCopy> downs;
  for (uint32_t m = 0; m < mips; ++m) downs.push_back(bufferRegion(offsets[m], m, 0, layers, mipExtent(e, m)));
  vkCmdCopyImageToBuffer(cb, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.buffer, uint32_t(downs.size()),
                         downs.data());
  submitAndWait(cb);
  acceptBlitQueueReports(mips - 1);

  ASSERT_EQ(std::memcmp(bytes(out), bytes(in), size_t(e.width) * e.height * layers * 4), 0);
  // Each level against the level above as read back (each level was rounded to 8 bits before the next was made).
  for (uint32_t m = 1; m < mips; ++m) {
    const VkExtent3D a = mipExtent(e, m - 1), b = mipExtent(e, m);
    const uint8_t* above = bytes(out) + offsets[m - 1];
    const uint8_t* level = bytes(out) + offsets[m];
    for (uint32_t l = 0; l < layers; ++l)
      for (uint32_t y = 0; y < b.height; ++y)
        for (uint32_t x = 0; x < b.width; ++x)
          for (uint32_t c = 0; c < 4; ++c) {
            const uint32_t xs[2] = {2 * x, std::min(2 * x + 1, a.width - 1)};
            const uint32_t ys[2] = {a.height > b.height ? 2 * y : y, a.height > b.height ? 2 * y + 1 : y};
            double sum = 0;
            for (uint32_t yy : ys)
              for (uint32_t xx : xs) sum += above[((l * a.height + yy) * a.width + xx) * 4 + c];
            EXPECT_TRUE(nearUnorm8(level[((l * b.height + y) * b.width + x) * 4 + c], sum / 4))
                << "mip " << m << " layer " << l << " (" << x << ", " << y << ") component " << c;
          }
  }
  destroy(in);
  destroy(out);
  destroy(img);
}

TEST_F(BlitTest, UpscalesSampleAtDestinationTexelCentres) {
  // A 3x2 RGBA32F source: NEAREST to 6x4 (each texel doubled), NEAREST to 7x4 and LINEAR to 7x3 (uneven scales);
  // the expectations follow "Image Copies With Scaling": u = (i + 1/2) * srcWidth / dstWidth, clamped to the edge.
  const uint32_t sw = 3, sh = 2;
  std::vector<float> texels(sw * sh * 4);
  for (uint32_t i = 0; i < texels.size(); ++i) texels[i] = float(i * i % 17) * 0.25f - 1.0f;
  std::vector<uint8_t> data(texels.size() * 4);
  std::memcpy(data.data(), texels.data(), data.size());
  auto srcAt = [&](int x, int y, int c) { return double(texels[(y * sw + x) * 4 + c]); };
  const VkImageCreateInfo srcInfo = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {sw, sh, 1}, 1, 1);

  struct Case {
    uint32_t w, h;
    VkFilter filter;
  };
  for (Case k : {Case{6, 4, VK_FILTER_NEAREST}, Case{7, 4, VK_FILTER_NEAREST}, Case{7, 3, VK_FILTER_LINEAR}}) {
    SCOPED_TRACE(testing::Message() << k.w << "x" << k.h << " filter " << k.filter);
    const VkImageCreateInfo dstInfo = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32G32B32A32_SFLOAT, {k.w, k.h, 1}, 1, 1);
    std::vector<uint8_t> got =
        blitAndRead(srcInfo, data, dstInfo, 0, 16, [&](VkCommandBuffer cb, VkImage s, VkImage d) {
          VkImageBlit r =
              blit(0, 0, {0, 0, 0}, {int32_t(sw), int32_t(sh), 1}, 0, 0, {0, 0, 0}, {int32_t(k.w), int32_t(k.h), 1});
          vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, k.filter);
        });
    acceptBlitQueueReports(1);
    for (uint32_t y = 0; y < k.h; ++y)
      for (uint32_t x = 0; x < k.w; ++x) {
        const double u = (x + 0.5) * sw / k.w, v = (y + 0.5) * sh / k.h;
        for (int c = 0; c < 4; ++c) {
          double want;
          if (k.filter == VK_FILTER_NEAREST) {
            want = srcAt(int(std::floor(u)), int(std::floor(v)), c);
          } else {
            const Taps tu = linearTaps(u, sw), tv = linearTaps(v, sh);
            want = 0;
            for (int b = 0; b < 2; ++b)
              for (int a = 0; a < 2; ++a) want += tu.w[a] * tv.w[b] * srcAt(tu.i[a], tv.i[b], c);
          }
          float g;
          std::memcpy(&g, got.data() + ((y * k.w + x) * 4 + c) * 4, 4);
          EXPECT_NEAR(g, want, 1e-5) << "(" << x << ", " << y << ") component " << c;
        }
      }
  }
}

TEST_F(BlitTest, ReversedOffsetsMirror) {
  // A 4x3 RGBA8_UINT image three times side by side into a 12x3 one, 1:1 (integers, NEAREST): mirrored in x by
  // reversed destination offsets, in y by reversed source offsets, and both (a half turn).
  const uint32_t w = 4, h = 3;
  std::vector<uint8_t> data(w * h * 4);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      for (uint32_t c = 0; c < 4; ++c) data[(y * w + x) * 4 + c] = pattern8(x, y, 0, c);
  std::vector<uint8_t> got =
      blitAndRead(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UINT, {w, h, 1}, 1, 1), data,
                  imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UINT, {3 * w, h, 1}, 1, 1), 0, 4,
                  [&](VkCommandBuffer cb, VkImage s, VkImage d) {
                    const int32_t W = w, H = h;
                    VkImageBlit r[3] = {blit(0, 0, {0, 0, 0}, {W, H, 1}, 0, 0, {W, 0, 0}, {0, H, 1}),
                                        blit(0, 0, {0, H, 0}, {W, 0, 1}, 0, 0, {W, 0, 0}, {2 * W, H, 1}),
                                        blit(0, 0, {W, H, 0}, {0, 0, 1}, 0, 0, {2 * W, 0, 0}, {3 * W, H, 1})};
                    vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 3, r, VK_FILTER_NEAREST);
                  });
  acceptBlitQueueReports(1);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x)
      for (uint32_t c = 0; c < 4; ++c) {
        auto at = [&](uint32_t dx) { return got[(y * 3 * w + dx) * 4 + c]; };
        EXPECT_EQ(at(x), pattern8(w - 1 - x, y, 0, c)) << "x mirror (" << x << ", " << y << ")";
        EXPECT_EQ(at(w + x), pattern8(x, h - 1 - y, 0, c)) << "y mirror (" << x << ", " << y << ")";
        EXPECT_EQ(at(2 * w + x), pattern8(w - 1 - x, h - 1 - y, 0, c)) << "half turn (" << x << ", " << y << ")";
      }
}

TEST_F(BlitTest, FormatConversions) {
  // 1:1 NEAREST blits of a 4x2 image between formats: the source is decoded to float (sRGB to linear), then
  // clamped and encoded (linear to sRGB); integers convert to integers of the same signedness, clamped.
  const VkExtent3D e{4, 2, 1};
  const uint32_t n = e.width * e.height;
  auto run = [&](VkFormat from, const std::vector<uint8_t>& data, VkFormat to, size_t dstTexel) {
    return blitFormats(e, from, data, to, dstTexel);
  };
  std::vector<uint8_t> rgba8(n * 4);
  for (uint32_t i = 0; i < rgba8.size(); ++i) rgba8[i] = uint8_t(i * 29 + 3);

  {  // UNORM -> SFLOAT (32 and 16 bits): v / 255
    SCOPED_TRACE("R8G8B8A8_UNORM -> R32G32B32A32_SFLOAT / R16G16B16A16_SFLOAT");
    std::vector<uint8_t> f32 = run(VK_FORMAT_R8G8B8A8_UNORM, rgba8, VK_FORMAT_R32G32B32A32_SFLOAT, 16);
    std::vector<uint8_t> f16 = run(VK_FORMAT_R8G8B8A8_UNORM, rgba8, VK_FORMAT_R16G16B16A16_SFLOAT, 8);
    for (uint32_t i = 0; i < n * 4; ++i) {
      float f;
      std::memcpy(&f, f32.data() + 4 * i, 4);
      EXPECT_NEAR(f, rgba8[i] / 255.0, 1e-7) << i;
      uint16_t h;
      std::memcpy(&h, f16.data() + 2 * i, 2);
      EXPECT_NEAR(halfToFloat(h), rgba8[i] / 255.0, 1.0 / 2048) << i;  // half precision: 11 significant bits
    }
  }
  {  // SRGB -> UNORM: colour decoded to linear, alpha as is
    SCOPED_TRACE("R8G8B8A8_SRGB -> R8G8B8A8_UNORM");
    std::vector<uint8_t> got = run(VK_FORMAT_R8G8B8A8_SRGB, rgba8, VK_FORMAT_R8G8B8A8_UNORM, 4);
    for (uint32_t i = 0; i < n * 4; ++i) {
      const double want = i % 4 == 3 ? rgba8[i] : 255.0 * srgbToLinear(rgba8[i] / 255.0);
      EXPECT_TRUE(nearUnorm8(got[i], want)) << i;
    }
  }
  {  // BGRA UNORM -> RGBA SRGB: the components are reordered and the colour encoded
    SCOPED_TRACE("B8G8R8A8_UNORM -> R8G8B8A8_SRGB");
    std::vector<uint8_t> got = run(VK_FORMAT_B8G8R8A8_UNORM, rgba8, VK_FORMAT_R8G8B8A8_SRGB, 4);
    for (uint32_t t = 0; t < n; ++t) {
      const uint8_t* s = &rgba8[t * 4];  // B, G, R, A in memory
      const uint8_t rgba[4] = {s[2], s[1], s[0], s[3]};
      for (int c = 0; c < 4; ++c) {
        const double want = c == 3 ? rgba[c] : 255.0 * linearToSrgb(rgba[c] / 255.0);
        EXPECT_TRUE(nearUnorm8(got[t * 4 + c], want)) << t << " " << c;
      }
    }
  }
  {  // SFLOAT -> UNORM clamps to [0, 1]; one-component SFLOAT -> SNORM fills G = B = 0, A = 1
    SCOPED_TRACE("R16G16B16A16_SFLOAT -> R8G8B8A8_UNORM, R32_SFLOAT -> R8G8B8A8_SNORM");
    const uint16_t halves[4] = {0x4000 /* 2 */, 0xbc00 /* -1 */, 0x3400 /* 0.25 */, 0x3c00 /* 1 */};
    std::vector<uint8_t> data(n * 8);
    for (uint32_t t = 0; t < n; ++t) std::memcpy(&data[t * 8], halves, 8);
    std::vector<uint8_t> got = run(VK_FORMAT_R16G16B16A16_SFLOAT, data, VK_FORMAT_R8G8B8A8_UNORM, 4);
    for (uint32_t t = 0; t < n; ++t) {
      EXPECT_EQ(got[t * 4 + 0], 255);
      EXPECT_EQ(got[t * 4 + 1], 0);
      EXPECT_EQ(got[t * 4 + 2], 64);  // 63.75 rounds to 64
      EXPECT_EQ(got[t * 4 + 3], 255);
    }
    std::vector<uint8_t> f32(n * 4);
    const float values[8] = {-0.25f, 0.5f, -3.0f, 1.0f, 0.0f, 0.125f, 7.0f, -1.0f};
    std::memcpy(f32.data(), values, sizeof values);
    got = run(VK_FORMAT_R32_SFLOAT, f32, VK_FORMAT_R8G8B8A8_SNORM, 4);
    for (uint32_t t = 0; t < n; ++t) {
      const double want = std::clamp(double(values[t]), -1.0, 1.0) * 127;  // -31.75, 63.5 (a tie), ...
      EXPECT_LE(std::fabs(int8_t(got[t * 4]) - want), 0.5 + 1e-3) << t;
      EXPECT_EQ(got[t * 4 + 1], 0);
      EXPECT_EQ(got[t * 4 + 2], 0);
      EXPECT_EQ(got[t * 4 + 3], 127);
    }
  }
  {  // Integers: clamped to the destination's range ("first clamping to the representable range")
    SCOPED_TRACE("R32_UINT -> R8_UINT, R32_SINT -> R8_SINT, R8_UINT -> R16G16B16A16_UINT");
    const uint32_t u[8] = {0, 7, 255, 256, 300, 65535, 0x80000000u, 0xffffffffu};
    const int32_t s[8] = {0, -5, 127, 128, -128, -129, 1000, -1000};
    std::vector<uint8_t> du(sizeof u), ds(sizeof s);
    std::memcpy(du.data(), u, sizeof u);
    std::memcpy(ds.data(), s, sizeof s);
    std::vector<uint8_t> gu = run(VK_FORMAT_R32_UINT, du, VK_FORMAT_R8_UINT, 1);
    std::vector<uint8_t> gs = run(VK_FORMAT_R32_SINT, ds, VK_FORMAT_R8_SINT, 1);
    std::vector<uint8_t> g4 = run(VK_FORMAT_R8_UINT, {9, 0, 255, 1, 2, 3, 4, 5}, VK_FORMAT_R16G16B16A16_UINT, 8);
    const uint8_t wideIn[8] = {9, 0, 255, 1, 2, 3, 4, 5};
    for (uint32_t t = 0; t < n; ++t) {
      EXPECT_EQ(gu[t], std::min<uint32_t>(u[t], 255)) << t;
      EXPECT_EQ(int8_t(gs[t]), std::clamp(s[t], -128, 127)) << t;
      uint16_t wide[4];
      std::memcpy(wide, &g4[t * 8], 8);
      EXPECT_EQ(wide[0], wideIn[t]) << t;
      EXPECT_EQ(wide[1], 0);
      EXPECT_EQ(wide[2], 0);
      EXPECT_EQ(wide[3], 1);  // a missing alpha reads as integer 1
    }
  }
}

TEST_F(BlitTest, PackedSixteenBitAndSharedExponentFormats) {
  // The packed formats of "Mandatory Format Support" (B4G4R4A4, R5G6B5, A1R5G5B5, A8B8G8R8, E5B9G9R9) uploaded as
  // bytes, blitted 1:1 (NEAREST) to RGBA32F and back from RGBA32F: each field where formats.adoc puts it, decoded as
  // value / (2^bits - 1) (the shared exponent: mantissa * 2^(exponent - 24)), encoded to the nearest field value.
  const VkExtent3D e{4, 2, 1};
  const uint32_t n = e.width * e.height;
  auto run = [&](VkFormat from, const std::vector<uint8_t>& data, VkFormat to, size_t dstTexel) {
    return blitFormats(e, from, data, to, dstTexel);
  };
  auto rgba32 = [&](const std::vector<uint8_t>& bytes, uint32_t t, int c) {
    float f;
    std::memcpy(&f, bytes.data() + 16 * t + 4 * c, 4);
    return f;
  };
  struct Field {
    int shift, bits;
  };
  struct Packed {
    VkFormat format;
    Field rgba[4];  // bits 0: absent (alpha reads 1)
  };
  const Packed packed[] = {
      {VK_FORMAT_R5G6B5_UNORM_PACK16, {{11, 5}, {5, 6}, {0, 5}, {0, 0}}},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, {{10, 5}, {5, 5}, {0, 5}, {15, 1}}},
      {VK_FORMAT_B4G4R4A4_UNORM_PACK16, {{4, 4}, {8, 4}, {12, 4}, {0, 4}}},
  };
  for (const Packed& p : packed) {
    SCOPED_TRACE(p.format);
    std::vector<uint8_t> words(n * 2);
    for (uint32_t i = 0; i < words.size(); ++i) words[i] = uint8_t(i * 71 + 13);
    const std::vector<uint8_t> f32 = run(p.format, words, VK_FORMAT_R32G32B32A32_SFLOAT, 16);
    std::vector<uint8_t> floats(n * 16);
    for (uint32_t t = 0; t < n; ++t) {
      uint16_t w;
      std::memcpy(&w, &words[2 * t], 2);
      for (int c = 0; c < 4; ++c) {
        const Field f = p.rgba[c];
        const double want = f.bits ? double((w >> f.shift) & ((1 << f.bits) - 1)) / ((1 << f.bits) - 1) : 1.0;
        EXPECT_NEAR(rgba32(f32, t, c), want, 1e-7) << t << " " << c;
        // The way back: values between the steps, which encode to the nearest step.
        const float v = float((t * 4 + c) % 9) / 8.0f;
        std::memcpy(&floats[16 * t + 4 * c], &v, 4);
      }
    }
    const std::vector<uint8_t> back = run(VK_FORMAT_R32G32B32A32_SFLOAT, floats, p.format, 2);
    for (uint32_t t = 0; t < n; ++t) {
      uint16_t w;
      std::memcpy(&w, &back[2 * t], 2);
      for (int c = 0; c < 4; ++c) {
        const Field f = p.rgba[c];
        if (!f.bits) continue;
        const double want = double((t * 4 + c) % 9) / 8.0 * ((1 << f.bits) - 1);
        EXPECT_LE(std::fabs(double((w >> f.shift) & ((1 << f.bits) - 1)) - want), 0.5 + 1e-6) << t << " " << c;
      }
    }
  }
  {  // A8B8G8R8_UNORM_PACK32: R in bits 0..7, A in 24..31 (the bytes of R8G8B8A8 on a little-endian host)
    SCOPED_TRACE("A8B8G8R8_UNORM_PACK32");
    std::vector<uint8_t> bytes(n * 4);
    for (uint32_t i = 0; i < bytes.size(); ++i) bytes[i] = uint8_t(i * 29 + 3);
    const std::vector<uint8_t> f32 = run(VK_FORMAT_A8B8G8R8_UNORM_PACK32, bytes, VK_FORMAT_R32G32B32A32_SFLOAT, 16);
    for (uint32_t t = 0; t < n; ++t) {
      uint32_t w;
      std::memcpy(&w, &bytes[4 * t], 4);
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(rgba32(f32, t, c), ((w >> (8 * c)) & 0xff) / 255.0, 1e-7) << t << c;
    }
  }
  {  // E5B9G9R9_UFLOAT_PACK32: R's mantissa in bits 0..8, G's 9..17, B's 18..26, the exponent in 27..31
    SCOPED_TRACE("E5B9G9R9_UFLOAT_PACK32");
    const uint32_t words[8] = {15u << 27 | 256,
                               16u << 27 | 511u << 9,
                               20u << 27 | 3u << 18 | 5,
                               0u,
                               31u << 27 | 511u << 18,
                               1u << 27 | 1u << 9,
                               24u << 27 | 1u | 2u << 9 | 3u << 18,
                               10u << 27 | 100u | 200u << 9 | 300u << 18};
    std::vector<uint8_t> data(sizeof words);
    std::memcpy(data.data(), words, sizeof words);
    const std::vector<uint8_t> f32 = run(VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, data, VK_FORMAT_R32G32B32A32_SFLOAT, 16);
    for (uint32_t t = 0; t < n; ++t) {
      const int exp = int(words[t] >> 27);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(rgba32(f32, t, c), std::ldexp(double((words[t] >> (9 * c)) & 511), exp - 24)) << t << " " << c;
      EXPECT_EQ(rgba32(f32, t, 3), 1.0f);
    }
  }
}

TEST_F(BlitTest, ClearColorImageEncodesPackedFormats) {
  // vkCmdClearColorImage through each packed format's encoder (R5G6B5, A1R5G5B5, B4G4R4A4, E5B9G9R9), read back as
  // bytes: the expected words are computed here from the fields' positions.
  struct Case {
    VkFormat format;
    VkClearColorValue color;
    uint32_t bytes, want;
  };
  const Case cases[] = {
      // R 0.5 * 31 = 15.5 -> 16 (ties to even), G 0.25 * 63 = 15.75 -> 16, B 1 -> 31
      {VK_FORMAT_R5G6B5_UNORM_PACK16, {{0.5f, 0.25f, 1.0f, 0.0f}}, 2, 16u << 11 | 16u << 5 | 31u},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, {{0.0f, 1.0f, 0.1f, 1.0f}}, 2, 1u << 15 | 0u << 10 | 31u << 5 | 3u},
      {VK_FORMAT_B4G4R4A4_UNORM_PACK16, {{0.2f, 0.4f, 1.0f, 0.6f}}, 2, 15u << 12 | 6u << 8 | 3u << 4 | 9u},
      // max 1.0: exponent 16, mantissas 256, 128, 64 (2^-8 per step)
      {VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, {{1.0f, 0.5f, 0.25f, 0.0f}}, 4, 16u << 27 | 64u << 18 | 128u << 9 | 256u},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.format);
    Img img = createImage(imageInfo(VK_IMAGE_TYPE_2D, c.format, {2, 2, 1}, 1, 1));
    HostBuffer out = createHostBuffer(4 * c.bytes, kXfer);
    std::memset(out.data, 0xee, 4 * c.bytes);
    VkCommandBuffer cb = beginOneTime();
    toGeneral(cb, img.image);
    VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, &c.color, 1, &all);
    sync(cb);
    VkBufferImageCopy down = bufferRegion(0, 0, 0, 1, {2, 2, 1});
    vkCmdCopyImageToBuffer(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, out.buffer, 1, &down);
    submitAndWait(cb);
    for (uint32_t t = 0; t < 4; ++t) {
      uint32_t w = 0;
      std::memcpy(&w, bytes(out) + t * c.bytes, c.bytes);
      EXPECT_EQ(w, c.want) << t;
    }
    destroy(out);
    destroy(img);
  }
}

TEST_F(BlitTest, ThreeDimensionalImages) {
  // A 4x4x4 R32_SFLOAT volume: halved in every dimension with LINEAR (the average of each 2x2x2 block), one slice
  // (z in [2, 3)) into a 2D image, and a 2D image stretched over the two slices of a 4x4x2 volume.
  const VkExtent3D e{4, 4, 4};
  std::vector<float> vol(64);
  for (uint32_t i = 0; i < 64; ++i) vol[i] = float(i) + 0.25f * float(i % 3);
  std::vector<uint8_t> data(256);
  std::memcpy(data.data(), vol.data(), 256);
  auto at = [&](uint32_t x, uint32_t y, uint32_t z) { return vol[(z * 4 + y) * 4 + x]; };
  const VkImageCreateInfo volInfo = imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, e, 1, 1);

  std::vector<uint8_t> half =
      blitAndRead(volInfo, data, imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, {2, 2, 2}, 1, 1), 0, 4,
                  [&](VkCommandBuffer cb, VkImage s, VkImage d) {
                    VkImageBlit r = blit(0, 0, {0, 0, 0}, {4, 4, 4}, 0, 0, {0, 0, 0}, {2, 2, 2});
                    vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_LINEAR);
                  });
  acceptBlitQueueReports(1);
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 2; ++x) {
        double sum = 0;
        for (uint32_t k = 0; k < 8; ++k) sum += at(2 * x + (k & 1), 2 * y + (k >> 1 & 1), 2 * z + (k >> 2));
        float g;
        std::memcpy(&g, half.data() + ((z * 2 + y) * 2 + x) * 4, 4);
        EXPECT_FLOAT_EQ(g, float(sum / 8)) << x << " " << y << " " << z;
      }

  std::vector<uint8_t> slice = blitAndRead(
      volInfo, data, imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32_SFLOAT, {4, 4, 1}, 1, 1), 0, 4,
      [&](VkCommandBuffer cb, VkImage s, VkImage d) {
        VkImageBlit r = blit(0, 0, {0, 0, 2}, {4, 4, 3}, 0, 0, {0, 0, 0}, {4, 4, 1});
        vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_NEAREST);
      });
  acceptBlitQueueReports(1);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      float g;
      std::memcpy(&g, slice.data() + (y * 4 + x) * 4, 4);
      EXPECT_EQ(g, at(x, y, 2)) << x << " " << y;
    }

  std::vector<uint8_t> flat(64);
  std::memcpy(flat.data(), vol.data(), 64);  // the first slice as a 4x4 2D image
  std::vector<uint8_t> stretched = blitAndRead(
      imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32_SFLOAT, {4, 4, 1}, 1, 1), flat,
      imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, {4, 4, 2}, 1, 1), 0, 4,
      [&](VkCommandBuffer cb, VkImage s, VkImage d) {
        VkImageBlit r = blit(0, 0, {0, 0, 0}, {4, 4, 1}, 0, 0, {0, 0, 0}, {4, 4, 2});
        vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_NEAREST);
      });
  acceptBlitQueueReports(1);
  for (uint32_t z = 0; z < 2; ++z)
    for (uint32_t i = 0; i < 16; ++i) {
      float g;
      std::memcpy(&g, stretched.data() + (z * 16 + i) * 4, 4);
      EXPECT_EQ(g, vol[i]) << "slice " << z << " texel " << i;
    }
}

TEST_F(BlitTest, LayersMipsOffsetsAndOneDimensionalImages) {
  // Layers 1..2 of an 8x8x3-layer source, the 4x4 square at (2, 1), into layers 0..1 of mip 1 (4x4) of an 8x8
  // two-mip three-layer destination, 1:1; the rest of the destination stays cleared.
  const VkExtent3D e{8, 8, 1};
  std::vector<uint8_t> data(8 * 8 * 3 * 4);
  for (uint32_t l = 0; l < 3; ++l)
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t x = 0; x < 8; ++x)
        for (uint32_t c = 0; c < 4; ++c) data[((l * 8 + y) * 8 + x) * 4 + c] = pattern8(x, y, l, c);
  const VkImageCreateInfo srcInfo = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, e, 1, 3);
  const VkImageCreateInfo dstInfo = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, e, 2, 3);
  auto record = [&](VkCommandBuffer cb, VkImage s, VkImage d) {
    VkImageBlit r = blit(0, 1, {2, 1, 0}, {6, 5, 1}, 1, 0, {0, 0, 0}, {4, 4, 1}, 2);
    vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_NEAREST);
  };
  std::vector<uint8_t> mip1 = blitAndRead(srcInfo, data, dstInfo, 1, 4, record);
  acceptBlitQueueReports(1);
  for (uint32_t l = 0; l < 3; ++l)
    for (uint32_t y = 0; y < 4; ++y)
      for (uint32_t x = 0; x < 4; ++x)
        for (uint32_t c = 0; c < 4; ++c)
          EXPECT_EQ(mip1[((l * 4 + y) * 4 + x) * 4 + c], l < 2 ? pattern8(2 + x, 1 + y, l + 1, c) : 0)
              << "layer " << l << " (" << x << ", " << y << ")";
  std::vector<uint8_t> mip0 = blitAndRead(srcInfo, data, dstInfo, 0, 4, record);
  acceptBlitQueueReports(1);
  EXPECT_EQ(mip0, std::vector<uint8_t>(mip0.size(), 0));

  // A 1D image of 8 RGBA32F texels, reversed and shrunk to 3 with LINEAR, into layer 1 of a 1D array image.
  std::vector<float> line(32);
  for (uint32_t i = 0; i < 32; ++i) line[i] = float(i % 4 == 3 ? 1 : i * 3 % 11);
  std::vector<uint8_t> lineData(128);
  std::memcpy(lineData.data(), line.data(), 128);
  std::vector<uint8_t> got =
      blitAndRead(imageInfo(VK_IMAGE_TYPE_1D, VK_FORMAT_R32G32B32A32_SFLOAT, {8, 1, 1}, 1, 1), lineData,
                  imageInfo(VK_IMAGE_TYPE_1D, VK_FORMAT_R32G32B32A32_SFLOAT, {3, 1, 1}, 1, 2), 0, 16,
                  [&](VkCommandBuffer cb, VkImage s, VkImage d) {
                    VkImageBlit r = blit(0, 0, {8, 0, 0}, {0, 1, 1}, 0, 1, {0, 0, 0}, {3, 1, 1});
                    vkCmdBlitImage(cb, s, VK_IMAGE_LAYOUT_GENERAL, d, VK_IMAGE_LAYOUT_GENERAL, 1, &r, VK_FILTER_LINEAR);
                  });
  acceptBlitQueueReports(1);
  for (uint32_t x = 0; x < 3; ++x) {
    const double u = (x + 0.5) * (0.0 - 8.0) / 3.0 + 8.0;  // the spec's mapping with srcOffsets reversed
    const Taps t = linearTaps(u, 8);
    for (int c = 0; c < 4; ++c) {
      const double want = t.w[0] * line[t.i[0] * 4 + c] + t.w[1] * line[t.i[1] * 4 + c];
      float g0, g1;
      std::memcpy(&g0, got.data() + (x * 4 + c) * 4, 4);
      std::memcpy(&g1, got.data() + ((3 + x) * 4 + c) * 4, 4);
      EXPECT_EQ(g0, 0.0f) << "layer 0 is not written";
      EXPECT_NEAR(g1, want, 1e-5) << x << " " << c;
    }
  }
}

class BlitCopyCommands2Test : public BlitTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.deviceExtensions = {VK_KHR_COPY_COMMANDS_2_EXTENSION_NAME};
    return o;
  }
};

TEST_F(BlitCopyCommands2Test, BlitImage2AndItsKhrAliasDownscaleSrgbInLinearSpace) {
  // A 4x2 sRGB image halved with LINEAR by vkCmdBlitImage2 and by vkCmdBlitImage2KHR: each result texel is the
  // average of two source texels taken in linear space ("sRGB ... converted to linear representation prior to
  // filtering"), then encoded again.
  auto blit2Khr = reinterpret_cast<PFN_vkCmdBlitImage2KHR>(vkGetDeviceProcAddr(device, "vkCmdBlitImage2KHR"));
  ASSERT_NE(blit2Khr, nullptr);
  ASSERT_NE(vkGetDeviceProcAddr(device, "vkCmdBlitImage2"), nullptr);
  std::vector<uint8_t> data(4 * 2 * 4);
  for (uint32_t i = 0; i < data.size(); ++i) data[i] = uint8_t(i * 71 + 13);
  for (bool khr : {false, true}) {
    SCOPED_TRACE(khr ? "vkCmdBlitImage2KHR" : "vkCmdBlitImage2");
    std::vector<uint8_t> got = blitAndRead(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_SRGB, {4, 2, 1}, 1, 1), data,
                                           imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_SRGB, {2, 2, 1}, 1, 1), 0, 4,
                                           [&](VkCommandBuffer cb, VkImage s, VkImage d) {
                                             VkImageBlit2 r{VK_STRUCTURE_TYPE_IMAGE_BLIT_2};
                                             r.srcSubresource = r.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                                             r.srcOffsets[1] = {4, 2, 1};
                                             r.dstOffsets[1] = {2, 2, 1};
                                             VkBlitImageInfo2 info{VK_STRUCTURE_TYPE_BLIT_IMAGE_INFO_2};
                                             info.srcImage = s;
                                             info.srcImageLayout = VK_IMAGE_LAYOUT_GENERAL;
                                             info.dstImage = d;
                                             info.dstImageLayout = VK_IMAGE_LAYOUT_GENERAL;
                                             info.regionCount = 1;
                                             info.pRegions = &r;
                                             info.filter = VK_FILTER_LINEAR;
                                             (khr ? blit2Khr : vkCmdBlitImage2)(cb, &info);
                                           });
    acceptBlitQueueReports(0, 1);
    for (uint32_t y = 0; y < 2; ++y)
      for (uint32_t x = 0; x < 2; ++x)
        for (uint32_t c = 0; c < 4; ++c) {
          const double a = data[(y * 4 + 2 * x) * 4 + c] / 255.0, b = data[(y * 4 + 2 * x + 1) * 4 + c] / 255.0;
          const double want =
              c == 3 ? 255.0 * (a + b) / 2 : 255.0 * linearToSrgb((srgbToLinear(a) + srgbToLinear(b)) / 2);
          EXPECT_TRUE(nearUnorm8(got[(y * 2 + x) * 4 + c], want)) << x << " " << y << " " << c;
        }
  }
}

class BlitMisuseTest : public BlitTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(BlitMisuseTest, EachRuleIsReportedByVuidAndTheValidNeighbourIsNot) {
  // Each invalid blit is reported with its VUID and records nothing: they all write into b (cleared to zero; the
  // sources are white), which stays zero. Valid neighbours (the same call with the one value fixed) are reported by
  // nothing, and write into c.
  const VkImageCreateInfo rgba = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, 2, 2);
  Img a = createImage(rgba), b = createImage(rgba), c = createImage(rgba);
  Img noSrc = createImage(
      imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, 1, 1, VK_IMAGE_USAGE_TRANSFER_DST_BIT));
  Img noDst = createImage(
      imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, 1, 1, VK_IMAGE_USAGE_TRANSFER_SRC_BIT));
  Img u8 = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UINT, {4, 4, 1}, 1, 1));
  Img u32 = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32_UINT, {4, 4, 1}, 1, 1));
  Img s32 = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32_SINT, {4, 4, 1}, 1, 1));
  Img s8 = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8_SINT, {4, 4, 1}, 1, 1));
  Img vol = createImage(imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 2}, 1, 1));
  Img line = createImage(imageInfo(VK_IMAGE_TYPE_1D, VK_FORMAT_R8G8B8A8_UNORM, {4, 1, 1}, 1, 1));
  HostBuffer out = createHostBuffer(512, kXfer);
  std::memset(out.data, 0xcd, out.size);
  const VkImageLayout G = VK_IMAGE_LAYOUT_GENERAL;
  const VkImageBlit whole = blit(0, 0, {0, 0, 0}, {4, 4, 1}, 0, 0, {0, 0, 0}, {4, 4, 1});

  VkCommandBuffer cb = beginOneTime();
  for (Img* i : {&a, &b, &c, &noSrc, &noDst, &u8, &u32, &s32, &s8, &vol, &line}) toGeneral(cb, i->image);
  VkClearColorValue white;
  white.float32[0] = white.float32[1] = white.float32[2] = white.float32[3] = 1.0f;
  VkClearColorValue zero{};
  VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
  for (Img* i : {&a, &vol, &line}) vkCmdClearColorImage(cb, i->image, G, &white, 1, &all);
  for (Img* i : {&b, &c}) vkCmdClearColorImage(cb, i->image, G, &zero, 1, &all);
  sync(cb);
  auto bad = [&](VkImage s, VkImageLayout sl, VkImage d, VkImageLayout dl, const VkImageBlit& r, VkFilter f,
                 const char* vuid) {
    SCOPED_TRACE(vuid);
    vkCmdBlitImage(cb, s, sl, d, dl, 1, &r, f);
    expectVkrtMessage(vuid);
  };
  auto good = [&](VkImage s, VkImage d, const VkImageBlit& r, VkFilter f, const char* neighbourOf) {
    SCOPED_TRACE(neighbourOf);
    vkCmdBlitImage(cb, s, G, d, G, 1, &r, f);
    EXPECT_TRUE(vkrtMessages().empty()) << "the valid neighbour of " << neighbourOf << " was reported";
    clearMessages();
    sync(cb);
  };

  bad(noSrc.image, G, b.image, G, whole, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00219");
  bad(a.image, G, noDst.image, G, whole, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstImage-00224");
  bad(a.image, VK_IMAGE_LAYOUT_UNDEFINED, b.image, G, whole, VK_FILTER_NEAREST,
      "VUID-vkCmdBlitImage-srcImageLayout-01398");
  bad(a.image, G, b.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, whole, VK_FILTER_NEAREST,
      "VUID-vkCmdBlitImage-dstImageLayout-01399");
  // Integer classes: unsigned with unsigned only, signed with signed only; LINEAR needs FILTER_LINEAR.
  bad(u8.image, G, b.image, G, whole, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00230");
  bad(s32.image, G, u32.image, G, whole, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00229");
  bad(a.image, G, s8.image, G, whole, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00229");
  good(u8.image, u32.image, whole, VK_FILTER_NEAREST, "00230 (UINT to UINT)");
  good(s32.image, s8.image, whole, VK_FILTER_NEAREST, "00229 (SINT to SINT)");
  bad(u8.image, G, u32.image, G, whole, VK_FILTER_LINEAR, "VUID-vkCmdBlitImage-filter-02001");
  bad(a.image, G, b.image, G, whole, VK_FILTER_CUBIC_EXT, "VUID-vkCmdBlitImage-filter-02002");
  bad(a.image, G, b.image, G, whole, VkFilter(7), "VUID-vkCmdBlitImage-filter-parameter");
  // Subresources.
  VkImageBlit r = whole;
  r.srcSubresource.mipLevel = 2;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcSubresource-01705");
  r = whole;
  r.dstSubresource.mipLevel = 2;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstSubresource-01706");
  r = whole;
  r.srcSubresource.layerCount = r.dstSubresource.layerCount = 3;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcSubresource-01707");
  r.srcSubresource.layerCount = 2;
  r.dstSubresource.baseArrayLayer = 1;
  r.dstSubresource.layerCount = 2;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstSubresource-01708");
  r = whole;
  r.dstSubresource.layerCount = 2;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-VkImageBlit-layerCount-00239");
  r = whole;
  r.srcSubresource.aspectMask = r.dstSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-aspectMask-00241");
  r.srcSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-VkImageBlit-aspectMask-00238");
  r.dstSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT | VK_IMAGE_ASPECT_DEPTH_BIT;
  r.srcSubresource.aspectMask = r.dstSubresource.aspectMask;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-aspectMask-00241");
  // 3D images: layer 0 alone on both sides.
  r = blit(0, 0, {0, 0, 0}, {4, 4, 2}, 0, 1, {0, 0, 0}, {4, 4, 1});
  bad(vol.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00240");
  // Offsets: inside [0, size] of the mip (size itself is the valid edge); 1D y and 1D/2D z are 0 and 1.
  r = whole;
  r.srcOffsets[1].x = 5;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcOffset-00243");
  r = whole;
  r.srcOffsets[0].y = -1;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcOffset-00244");
  r = blit(0, 0, {0, 0, 0}, {4, 4, 3}, 0, 0, {0, 0, 0}, {4, 4, 1});
  bad(vol.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcOffset-00246");
  r = blit(0, 0, {0, 0, 0}, {4, 2, 1}, 0, 0, {0, 0, 0}, {4, 4, 1});
  bad(line.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00245");
  r = whole;
  r.srcOffsets[1].z = 2;
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-srcImage-00247");
  r = whole;
  r.dstSubresource.mipLevel = 1;  // 2x2
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstOffset-00248");
  r.dstOffsets[1] = {2, 3, 1};
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstOffset-00249");
  r = blit(0, 0, {0, 0, 0}, {4, 4, 1}, 0, 0, {0, 0, 0}, {4, 4, 3});
  bad(a.image, G, vol.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstOffset-00251");
  r = blit(0, 0, {0, 0, 0}, {4, 4, 1}, 0, 0, {0, 1, 0}, {4, 0, 1});
  bad(a.image, G, line.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstImage-00250");
  r = blit(0, 0, {0, 0, 0}, {4, 4, 1}, 0, 0, {0, 0, 1}, {4, 4, 0});
  bad(a.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-dstImage-00252");
  // Overlap within one image: a destination box meeting a source box of the same mip and layer (pRegions-00217),
  // within one region or across two; another mip, or disjoint boxes, are fine.
  r = blit(0, 0, {0, 0, 0}, {2, 2, 1}, 0, 0, {1, 1, 0}, {3, 3, 1});
  bad(b.image, G, b.image, G, r, VK_FILTER_NEAREST, "VUID-vkCmdBlitImage-pRegions-00217");
  VkImageBlit two[2] = {blit(0, 0, {0, 0, 0}, {2, 2, 1}, 0, 0, {2, 2, 0}, {4, 4, 1}),
                        blit(0, 0, {2, 2, 0}, {4, 4, 1}, 0, 0, {0, 0, 0}, {2, 2, 1})};
  vkCmdBlitImage(cb, b.image, G, b.image, G, 2, two, VK_FILTER_NEAREST);  // each destination is the other's source
  expectVkrtMessage("VUID-vkCmdBlitImage-pRegions-00217");
  sync(cb);

  // Valid neighbours that write into c: offsets at the edge (x = width, mirrored), a same-image blit into another
  // mip, disjoint boxes in one mip, a 3D slice and a 1D image with their offsets right.
  r = whole;
  r.dstOffsets[0] = {4, 0, 0};
  r.dstOffsets[1] = {0, 4, 1};
  good(a.image, c.image, r, VK_FILTER_NEAREST, "00243/00248 (offsets at the edge, mirrored)");
  good(c.image, c.image, blit(0, 0, {0, 0, 0}, {4, 4, 1}, 1, 0, {0, 0, 0}, {2, 2, 1}), VK_FILTER_LINEAR,
       "00217 (another mip of the same image)");
  good(c.image, c.image, blit(1, 0, {0, 0, 0}, {1, 1, 1}, 1, 0, {1, 1, 0}, {2, 2, 1}), VK_FILTER_NEAREST,
       "00217 (disjoint boxes in one mip)");
  good(vol.image, c.image, blit(0, 0, {0, 0, 1}, {4, 4, 2}, 0, 0, {0, 0, 0}, {4, 4, 1}), VK_FILTER_NEAREST,
       "00240/00246 (a 3D slice)");
  good(line.image, c.image, blit(0, 0, {0, 0, 0}, {4, 1, 1}, 0, 0, {0, 0, 0}, {4, 1, 1}), VK_FILTER_NEAREST,
       "00245 (1D offsets 0 and 1)");
  VkBufferImageCopy down[4] = {bufferRegion(0, 0, 0, 2, {4, 4, 1}), bufferRegion(128, 1, 0, 2, {2, 2, 1}),
                               bufferRegion(256, 0, 0, 2, {4, 4, 1}), bufferRegion(384, 1, 0, 2, {2, 2, 1})};
  vkCmdCopyImageToBuffer(cb, b.image, G, out.buffer, 2, down);
  vkCmdCopyImageToBuffer(cb, c.image, G, out.buffer, 2, down + 2);
  submitAndWait(cb);
  // b is all zero; c's mip 0 layer 0 and mip 1 layer 0 are white, its layer 1 zero.
  for (int i = 0; i < 160; ++i) EXPECT_EQ(bytes(out)[i], 0) << "b, byte " << i;
  for (int i = 0; i < 160; ++i) {
    const bool white = i < 64 || (i >= 128 && i < 144);
    EXPECT_EQ(bytes(out)[256 + i], white ? 255 : 0) << "c, byte " << i;
  }
  for (Img* i : {&a, &b, &c, &noSrc, &noDst, &u8, &u32, &s32, &s8, &vol, &line}) destroy(*i);
  destroy(out);
}

TEST_F(BlitMisuseTest, BlitImage2ReportsItsOwnVuids) {
  Img a = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, 1, 1));
  Img u = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UINT, {4, 4, 1}, 1, 1));
  VkCommandBuffer cb = beginOneTime();
  toGeneral(cb, a.image);
  toGeneral(cb, u.image);
  VkImageBlit2 r{VK_STRUCTURE_TYPE_IMAGE_BLIT_2};
  r.srcSubresource = r.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r.srcOffsets[1] = r.dstOffsets[1] = {4, 4, 1};
  VkBlitImageInfo2 info{VK_STRUCTURE_TYPE_BLIT_IMAGE_INFO_2};
  info.srcImage = u.image;
  info.srcImageLayout = info.dstImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  info.dstImage = u.image;
  info.regionCount = 1;
  info.pRegions = &r;
  info.filter = VK_FILTER_LINEAR;
  vkCmdBlitImage2(cb, &info);
  expectVkrtMessage("VUID-VkBlitImageInfo2-filter-02001");
  info.filter = VK_FILTER_NEAREST;
  info.dstImage = a.image;
  vkCmdBlitImage2(cb, &info);
  expectVkrtMessage("VUID-VkBlitImageInfo2-srcImage-00230");
  info.srcImage = a.image;
  r.dstOffsets[1].y = 5;
  vkCmdBlitImage2(cb, &info);
  expectVkrtMessage("VUID-VkBlitImageInfo2-dstOffset-00249");
  r.dstOffsets[1].y = 4;
  r.dstSubresource.layerCount = 2;
  vkCmdBlitImage2(cb, &info);
  expectVkrtMessage("VUID-VkImageBlit2-layerCount-00239");
  submitAndWait(cb);
  destroy(a);
  destroy(u);
}

}  // namespace
}  // namespace vkrt::test
