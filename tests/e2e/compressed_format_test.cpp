// The BC formats (textureCompressionBC) end to end with the validation layer on: blocks uploaded and read back
// through buffer copies (mip levels smaller than a block included), every texel of two blocks of each of the
// sixteen formats fetched in a compute shader, LINEAR filtering across a block edge, the address modes and a
// gather, a blit from BC1 to RGBA8, copies between BC7 and R32G32B32A32_UINT images, an uncompressed view of a
// block-texel-view-compatible image, and the copy rules of compressed formats (vkrt's reports with the layer off).
//
// The blocks are built here bit by bit, and the expected texels computed from the same fields with the formulas
// of the Khronos Data Format Specification ("S3TC", "RGTC", "BPTC"), independently of vkrt's decoders.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <vector>

#include "compressed_block_view.comp.spv.h"
#include "compressed_read.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/image_fixture.hpp"

namespace vkrt::test {
namespace {

using Texel = std::array<float, 4>;
using Block = std::vector<uint8_t>;

// A little-endian bit writer over a block.
struct Bits {
  Block b;
  uint32_t at = 0;
  explicit Bits(size_t bytes) : b(bytes, 0) {}
  void put(uint64_t v, uint32_t n) {
    for (uint32_t i = 0; i < n; ++i, ++at)
      if ((v >> i) & 1) b[at / 8] |= uint8_t(1u << (at % 8));
  }
};

// ---- BC1 (and the colour half of BC2/BC3): two RGB565 colours and 2-bit indices.
Block bc1(uint16_t c0, uint16_t c1, const uint32_t idx[16]) {
  Bits w(8);
  w.put(c0, 16);
  w.put(c1, 16);
  for (int t = 0; t < 16; ++t) w.put(idx[t], 2);
  return w.b;
}
Texel rgb565(uint16_t c) { return {float(c >> 11) / 31.0f, float((c >> 5) & 63) / 63.0f, float(c & 31) / 31.0f, 1}; }
// The palette entry; `fourColour`: BC2/BC3 always, BC1 when c0 > c1. Index 3 of BC1's three-colour mode is black
// with alpha 0 (BC1_RGBA; BC1_RGB reads alpha 1).
Texel bc1Colour(uint16_t c0, uint16_t c1, uint32_t i, bool fourColour) {
  Texel a = rgb565(c0), b = rgb565(c1), r{0, 0, 0, 1};
  for (int k = 0; k < 3; ++k) {
    if (fourColour)
      r[k] = i == 0 ? a[k] : i == 1 ? b[k] : i == 2 ? (2 * a[k] + b[k]) / 3 : (a[k] + 2 * b[k]) / 3;
    else
      r[k] = i == 0 ? a[k] : i == 1 ? b[k] : i == 2 ? (a[k] + b[k]) / 2 : 0;
  }
  if (!fourColour && i == 3) r[3] = 0;
  return r;
}

// ---- BC4 (and BC3's alpha, BC5's channels): two 8-bit endpoints and 3-bit indices.
Block bc4(uint8_t e0, uint8_t e1, const uint32_t idx[16]) {
  Bits w(8);
  w.put(e0, 8);
  w.put(e1, 8);
  for (int t = 0; t < 16; ++t) w.put(idx[t], 3);
  return w.b;
}
float bc4Value(uint8_t r0, uint8_t r1, uint32_t i, bool snorm) {
  const float a = snorm ? std::max(float(int8_t(r0)) / 127.0f, -1.0f) : float(r0) / 255.0f;
  const float b = snorm ? std::max(float(int8_t(r1)) / 127.0f, -1.0f) : float(r1) / 255.0f;
  if (i == 0) return a;
  if (i == 1) return b;
  const bool eight = snorm ? int8_t(r0) > int8_t(r1) : r0 > r1;
  if (eight) return (float(8 - i) * a + float(i - 1) * b) / 7.0f;
  if (i == 6) return snorm ? -1.0f : 0.0f;
  if (i == 7) return 1.0f;
  return (float(6 - i) * a + float(i - 1) * b) / 5.0f;
}

// ---- BC7 mode 6: one subset, RGBA endpoints of 7 bits and a p-bit each, 4-bit indices (texel 0's top bit
// implied 0).
constexpr int kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};
struct Bc7Mode6 {
  uint8_t c[2][4];  // 7-bit endpoints, RGBA
  uint8_t p[2];
  uint32_t idx[16];
  Block encode() const {
    Bits w(16);
    w.put(1u << 6, 7);
    for (int ch = 0; ch < 4; ++ch)
      for (int e = 0; e < 2; ++e) w.put(c[e][ch], 7);
    w.put(p[0], 1);
    w.put(p[1], 1);
    for (int t = 0; t < 16; ++t) w.put(idx[t], t == 0 ? 3 : 4);
    return w.b;
  }
  Texel texel(int t) const {
    Texel r;
    for (int ch = 0; ch < 4; ++ch) {
      const int e0 = (c[0][ch] << 1) | p[0], e1 = (c[1][ch] << 1) | p[1], wt = kWeights4[idx[t]];
      r[ch] = float(((64 - wt) * e0 + wt * e1 + 32) >> 6) / 255.0f;
    }
    return r;
  }
};

// ---- BC6H mode 11 (mode bits 00011): one region, untransformed 10-bit RGB endpoints, 4-bit indices.
float halfToFloat(uint32_t h) {
  const uint32_t e = (h >> 10) & 31, m = h & 1023;
  const float v = e == 0 ? std::ldexp(float(m), -24) : std::ldexp(float(m | 1024), int(e) - 25);
  return (h & 0x8000) ? -v : v;
}
struct Bc6hMode11 {
  int32_t e[2][3];  // endpoints, RGB (signed for SFLOAT)
  uint32_t idx[16];
  Block encode() const {
    Bits w(16);
    w.put(3, 5);
    for (int k = 0; k < 2; ++k)
      for (int ch = 0; ch < 3; ++ch) w.put(uint32_t(e[k][ch]) & 1023u, 10);
    for (int t = 0; t < 16; ++t) w.put(idx[t], t == 0 ? 3 : 4);
    return w.b;
  }
  static int32_t unquantize(int32_t c, bool sgn) {
    if (!sgn) return c == 0 ? 0 : c == 1023 ? 0xFFFF : ((c << 16) + 0x8000) >> 10;
    const bool neg = c < 0;
    const int32_t a = neg ? -c : c;
    const int32_t u = a == 0 ? 0 : a >= 511 ? 0x7FFF : ((a << 15) + 0x4000) >> 9;
    return neg ? -u : u;
  }
  Texel texel(int t, bool sgn) const {
    Texel r{0, 0, 0, 1};
    for (int ch = 0; ch < 3; ++ch) {
      const int32_t a = unquantize(e[0][ch], sgn), b = unquantize(e[1][ch], sgn), wt = kWeights4[idx[t]];
      const int32_t v = (a * (64 - wt) + b * wt + 32) >> 6;
      uint32_t h;
      if (!sgn)
        h = uint32_t((v * 31) >> 6);
      else
        h = v < 0 ? 0x8000u | uint32_t(((-v) * 31) >> 5) : uint32_t((v * 31) >> 5);
      r[ch] = halfToFloat(h);
    }
    return r;
  }
};

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// One format's two blocks (an 8x4 image) and the texel (x, y) they decode to.
struct Case {
  VkFormat format;
  Block blocks;  // block 0 then block 1
  std::function<Texel(int x, int y)> texel;
  float tolerance;
};

uint32_t kIdx4[16], kIdx8[16], kIdxRev8[16], kIdx16[16];
const bool kIdxInit = [] {
  for (int t = 0; t < 16; ++t) {
    kIdx4[t] = uint32_t(t % 4);
    kIdx8[t] = uint32_t(t % 8);
    kIdxRev8[t] = uint32_t(7 - (t + 3) % 8);
    kIdx16[t] = uint32_t(t);
  }
  kIdx16[0] = 0;  // an anchor index has one bit less
  return true;
}();

Block cat(Block a, const Block& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Every BC format: block 0 and block 1 of a 2x1-block image, with gradients through every index.
std::vector<Case> allCases() {
  std::vector<Case> cases;
  const float t8 = 1.5f / 255.0f;  // decoders may interpolate 8-bit values in integers
  auto blockOf = [](int x) { return x / 4; };
  auto texOf = [](int x, int y) { return (y % 4) * 4 + x % 4; };
  // BC1: block 0 four colours (red > blue), block 1 three colours and transparent black (c0 <= c1).
  const uint16_t red = 0xF800, blue = 0x001F, green = 0x07E0, white = 0xFFFF;
  for (bool rgba : {false, true})
    for (bool srgb : {false, true}) {
      const VkFormat f = rgba ? (srgb ? VK_FORMAT_BC1_RGBA_SRGB_BLOCK : VK_FORMAT_BC1_RGBA_UNORM_BLOCK)
                              : (srgb ? VK_FORMAT_BC1_RGB_SRGB_BLOCK : VK_FORMAT_BC1_RGB_UNORM_BLOCK);
      cases.push_back({f, cat(bc1(red, blue, kIdx4), bc1(green, white, kIdx4)),
                       [=](int x, int y) {
                         const int t = texOf(x, y);
                         Texel r = blockOf(x) == 0 ? bc1Colour(red, blue, kIdx4[t], true)
                                                   : bc1Colour(green, white, kIdx4[t], false);
                         if (!rgba) r[3] = 1;
                         if (srgb)
                           for (int k = 0; k < 3; ++k) r[k] = srgbToLinear(r[k]);
                         return r;
                       },
                       t8});
    }
  // BC2: 4-bit explicit alpha (texel t: t / 15), then a BC1 colour block in four-colour mode.
  for (bool srgb : {false, true}) {
    Bits alpha(8);
    for (int t = 0; t < 16; ++t) alpha.put(uint32_t(t), 4);
    const Block b0 = cat(alpha.b, bc1(red, blue, kIdx4)), b1 = cat(alpha.b, bc1(white, green, kIdx4));
    cases.push_back({srgb ? VK_FORMAT_BC2_SRGB_BLOCK : VK_FORMAT_BC2_UNORM_BLOCK, cat(b0, b1),
                     [=](int x, int y) {
                       const int t = texOf(x, y);
                       Texel r = blockOf(x) == 0 ? bc1Colour(red, blue, kIdx4[t], true)
                                                 : bc1Colour(white, green, kIdx4[t], true);
                       r[3] = float(t) / 15.0f;
                       if (srgb)
                         for (int k = 0; k < 3; ++k) r[k] = srgbToLinear(r[k]);
                       return r;
                     },
                     t8});
  }
  // BC3: a BC4 alpha block (eight values in block 0, six and 0/1 in block 1), then the colour block.
  for (bool srgb : {false, true}) {
    const Block b0 = cat(bc4(255, 0, kIdx8), bc1(red, blue, kIdx4));
    const Block b1 = cat(bc4(40, 200, kIdx8), bc1(blue, red, kIdx4));  // blue < red: still four colours
    cases.push_back({srgb ? VK_FORMAT_BC3_SRGB_BLOCK : VK_FORMAT_BC3_UNORM_BLOCK, cat(b0, b1),
                     [=](int x, int y) {
                       const int t = texOf(x, y);
                       const bool first = blockOf(x) == 0;
                       Texel r = first ? bc1Colour(red, blue, kIdx4[t], true) : bc1Colour(blue, red, kIdx4[t], true);
                       r[3] = first ? bc4Value(255, 0, kIdx8[t], false) : bc4Value(40, 200, kIdx8[t], false);
                       if (srgb)
                         for (int k = 0; k < 3; ++k) r[k] = srgbToLinear(r[k]);
                       return r;
                     },
                     t8});
  }
  // BC4 UNORM / SNORM: R only (G, B 0, A 1). SNORM: 127 and -127 (eight values), then -128 (-1) and 100 (six).
  cases.push_back({VK_FORMAT_BC4_UNORM_BLOCK, cat(bc4(250, 10, kIdx8), bc4(10, 250, kIdxRev8)),
                   [=](int x, int y) {
                     const int t = texOf(x, y);
                     const float r =
                         blockOf(x) == 0 ? bc4Value(250, 10, kIdx8[t], false) : bc4Value(10, 250, kIdxRev8[t], false);
                     return Texel{r, 0, 0, 1};
                   },
                   t8});
  cases.push_back({VK_FORMAT_BC4_SNORM_BLOCK, cat(bc4(127, uint8_t(-127), kIdx8), bc4(uint8_t(-128), 100, kIdxRev8)),
                   [=](int x, int y) {
                     const int t = texOf(x, y);
                     const float r = blockOf(x) == 0 ? bc4Value(127, uint8_t(-127), kIdx8[t], true)
                                                     : bc4Value(uint8_t(-128), 100, kIdxRev8[t], true);
                     return Texel{r, 0, 0, 1};
                   },
                   t8});
  // BC5 UNORM / SNORM: R then G, each a BC4 block (B 0, A 1).
  for (bool snorm : {false, true}) {
    const uint8_t a0 = snorm ? 127 : 255, a1 = snorm ? uint8_t(-127) : 0, g0 = snorm ? uint8_t(-60) : 30,
                  g1 = snorm ? 90 : 220;
    const Block b0 = cat(bc4(a0, a1, kIdx8), bc4(g0, g1, kIdxRev8));
    const Block b1 = cat(bc4(g1, g0, kIdx8), bc4(a1, a0, kIdxRev8));
    cases.push_back({snorm ? VK_FORMAT_BC5_SNORM_BLOCK : VK_FORMAT_BC5_UNORM_BLOCK, cat(b0, b1),
                     [=](int x, int y) {
                       const int t = texOf(x, y);
                       if (blockOf(x) == 0)
                         return Texel{bc4Value(a0, a1, kIdx8[t], snorm), bc4Value(g0, g1, kIdxRev8[t], snorm), 0, 1};
                       return Texel{bc4Value(g1, g0, kIdx8[t], snorm), bc4Value(a1, a0, kIdxRev8[t], snorm), 0, 1};
                     },
                     t8});
  }
  // BC6H mode 11: UFLOAT a gradient from 0 to the largest half and a solid block; SFLOAT a negative solid block
  // and a positive gradient.
  for (bool sgn : {false, true}) {
    Bc6hMode11 g{}, s{};
    for (int ch = 0; ch < 3; ++ch) {
      g.e[0][ch] = 0;
      g.e[1][ch] = sgn ? 511 : 1023;
      s.e[0][ch] = s.e[1][ch] = sgn ? -300 + 100 * ch : 512 + 100 * ch;
    }
    g.e[0][1] = sgn ? 200 : 300;  // green from 200 / 300 up
    std::copy(kIdx16, kIdx16 + 16, g.idx);
    std::copy(kIdx16, kIdx16 + 16, s.idx);
    cases.push_back({sgn ? VK_FORMAT_BC6H_SFLOAT_BLOCK : VK_FORMAT_BC6H_UFLOAT_BLOCK,
                     sgn ? cat(s.encode(), g.encode()) : cat(g.encode(), s.encode()),
                     [=](int x, int y) {
                       const int t = texOf(x, y);
                       const bool grad = (blockOf(x) == 0) != sgn;
                       return grad ? g.texel(t, sgn) : s.texel(t, sgn);
                     },
                     1e-6f});
  }
  // BC7 mode 6: a gradient through all sixteen weights (R up, G down, B and A almost constant) and a solid block.
  for (bool srgb : {false, true}) {
    Bc7Mode6 g{{{0, 127, 64, 127}, {127, 0, 64, 127}}, {0, 1}, {}};
    Bc7Mode6 s{{{100, 20, 70, 90}, {100, 20, 70, 90}}, {1, 1}, {}};
    std::copy(kIdx16, kIdx16 + 16, g.idx);
    std::copy(kIdx16, kIdx16 + 16, s.idx);
    cases.push_back({srgb ? VK_FORMAT_BC7_SRGB_BLOCK : VK_FORMAT_BC7_UNORM_BLOCK, cat(g.encode(), s.encode()),
                     [=](int x, int y) {
                       const int t = texOf(x, y);
                       Texel r = blockOf(x) == 0 ? g.texel(t) : s.texel(t);
                       if (srgb)
                         for (int k = 0; k < 3; ++k) r[k] = srgbToLinear(r[k]);
                       return r;
                     },
                     2e-6f});
  }
  return cases;
}

class CompressedFormatTest : public ImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features.textureCompressionBC = VK_TRUE;
    o.features12.samplerMirrorClampToEdge = VK_TRUE;  // FilteringAddressModesAndGathersReadAcrossBlocks
    return o;
  }

  struct Tex {
    Img img;
    VkImageView view = VK_NULL_HANDLE;
    VkImageCreateInfo ci{};
  };

  // A 2D image of `format` whose mip levels hold `levels` (each a level's blocks, row after row), uploaded through
  // vkCmdCopyBufferToImage (each level's extent in texels, a level smaller than a block included) and left in
  // SHADER_READ_ONLY_OPTIMAL; with a view of every level.
  Tex upload(VkFormat format, VkExtent3D extent, const std::vector<Block>& levels, VkImageUsageFlags usage = 0,
             VkImageCreateFlags flags = 0) {
    Tex t;
    t.ci = imageInfo(VK_IMAGE_TYPE_2D, format, extent, uint32_t(levels.size()), 1,
                     kImgXfer | VK_IMAGE_USAGE_SAMPLED_BIT | usage);
    t.ci.flags = flags;
    t.img = createImage(t.ci);
    VkDeviceSize bytes = 0;
    for (const Block& l : levels) bytes += l.size();
    HostBuffer staging = createHostBuffer(bytes, kXfer);
    std::vector<VkBufferImageCopy> regions;
    VkDeviceSize at = 0;
    for (uint32_t m = 0; m < levels.size(); ++m) {
      std::memcpy(bytes_(staging) + at, levels[m].data(), levels[m].size());
      VkBufferImageCopy r{};
      r.bufferOffset = at;
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
      r.imageExtent = {std::max(1u, extent.width >> m), std::max(1u, extent.height >> m), 1};
      regions.push_back(r);
      at += levels[m].size();
    }
    VkCommandBuffer cb = beginOneTime();
    toDst(cb, t.img.image);
    vkCmdCopyBufferToImage(cb, staging.buffer, t.img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           uint32_t(regions.size()), regions.data());
    transition(cb, t.img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    submitAndWait(cb);
    destroy(staging);
    // A view of the compressed format is sampled only (the image's storage usage is for its uncompressed views).
    VkImageViewUsageCreateInfo vu{VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO};
    vu.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, &vu};
    vi.image = t.img.image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, 1};
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &t.view), VK_SUCCESS);
    return t;
  }
  static uint8_t* bytes_(const HostBuffer& b) { return static_cast<uint8_t*>(b.data); }
  void writeBuffer(const ComputePipeline& p, uint32_t binding, const HostBuffer& b) {
    VkDescriptorBufferInfo bi{b.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = binding;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void TearDown() override {
    if (nearest_) vkDestroySampler(device, nearest_, nullptr);
    ImageTest::TearDown();
  }
  // A NEAREST sampler with CLAMP_TO_EDGE, made once per test.
  VkSampler nearestSampler() {
    if (!nearest_) nearest_ = sampler(VK_FILTER_NEAREST, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
    return nearest_;
  }
  VkSampler nearest_ = VK_NULL_HANDLE;
  void destroy(Tex& t) {
    vkDestroyImageView(device, t.view, nullptr);
    destroy(t.img);
  }
  using ImageTest::destroy;

  VkSampler sampler(VkFilter filter, VkSamplerAddressMode mode,
                    VkBorderColor border = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = filter;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = mode;
    si.borderColor = border;
    si.maxLod = VK_LOD_CLAMP_NONE;
    VkSampler s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSampler(device, &si, nullptr, &s), VK_SUCCESS);
    return s;
  }

  // Runs compressed_read.comp on `view` with `smp`: mode 0 fetches `count` texels of level `lod`, rows of `width`;
  // modes 1 (textureLod) and 2 (textureGather) read at `coords` (u, v, lod).
  std::vector<Texel> read(VkImageView view, VkSampler smp, int mode, int count, int width, int lod,
                          const std::vector<Texel>& coords = {}) {
    ComputePipeline p = makeComputePipeline(device, kSpv_compressed_read_comp, sizeof kSpv_compressed_read_comp,
                                            {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                                             VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                                            16);
    EXPECT_EQ(p.result, VK_SUCCESS);
    HostBuffer in = createHostBuffer(std::max<size_t>(16, coords.size() * 16), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (!coords.empty()) std::memcpy(in.data, coords.data(), coords.size() * 16);
    HostBuffer out = createHostBuffer(size_t(count) * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0xff, size_t(count) * 16);
    writeBuffer(p, 1, in);
    writeBuffer(p, 2, out);
    VkDescriptorImageInfo ii{smp, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.dstBinding = 0;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    const int32_t push[4] = {mode, count, width, lod};
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 16, push);
    vkCmdDispatch(cb, uint32_t(count + 15) / 16, 1, 1);
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
    submitAndWait(cb);
    std::vector<Texel> r(static_cast<size_t>(count));
    std::memcpy(r.data(), out.data, size_t(count) * 16);
    destroy(in);
    destroy(out);
    vkDestroyPipeline(device, p.pipeline, nullptr);
    vkDestroyShaderModule(device, p.module, nullptr);
    vkDestroyDescriptorPool(device, p.pool, nullptr);
    vkDestroyPipelineLayout(device, p.layout, nullptr);
    vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
    return r;
  }

  // The image's level `mip` read back through vkCmdCopyImageToBuffer (the level's extent in texels).
  Block readBack(VkImage image, uint32_t mip, VkExtent3D extent, size_t bytes, VkImageLayout layout) {
    HostBuffer b = createHostBuffer(bytes, kXfer);
    std::memset(b.data, 0xcd, bytes);
    VkCommandBuffer cb = beginOneTime();
    transition(cb, image, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, 1};
    r.imageExtent = extent;
    vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, b.buffer, 1, &r);
    transition(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout);
    submitAndWait(cb);
    Block out(bytes_(b), bytes_(b) + bytes);
    destroy(b);
    return out;
  }
};

void expectNear(const Texel& got, const Texel& want, float tol, const char* what, int i) {
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(got[k], want[k], tol * std::max(1.0f, std::fabs(want[k])))
        << what << " texel " << i << " component " << k;
}

// The properties the spec's "Mandatory format support: BC compressed formats" table asks, for 2D and 3D images,
// arrays and cube-compatible ones, and nothing that would write a block.
TEST_F(CompressedFormatTest, FormatPropertiesFollowTheMandatoryTable) {
  VkPhysicalDeviceFeatures f;
  vkGetPhysicalDeviceFeatures(physicalDevice, &f);
  ASSERT_TRUE(f.textureCompressionBC);
  const VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT |
                                    VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT |
                                    VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  for (int fmt = VK_FORMAT_BC1_RGB_UNORM_BLOCK; fmt <= VK_FORMAT_BC7_SRGB_BLOCK; ++fmt) {
    SCOPED_TRACE(fmt);
    VkFormatProperties p;
    vkGetPhysicalDeviceFormatProperties(physicalDevice, VkFormat(fmt), &p);
    EXPECT_EQ(p.optimalTilingFeatures & need, need);
    if (onVkrt()) {
      EXPECT_EQ(p.optimalTilingFeatures, need);  // no attachment, storage or blit destination
      EXPECT_EQ(p.linearTilingFeatures, 0u);
      EXPECT_EQ(p.bufferFeatures, 0u);
    }
    VkImageFormatProperties ip;
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_SAMPLED_BIT | kImgXfer;
    EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties(physicalDevice, VkFormat(fmt), VK_IMAGE_TYPE_2D,
                                                       VK_IMAGE_TILING_OPTIMAL, usage, 0, &ip),
              VK_SUCCESS);
    EXPECT_GE(ip.maxArrayLayers, 6u);
    EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties(physicalDevice, VkFormat(fmt), VK_IMAGE_TYPE_2D,
                                                       VK_IMAGE_TILING_OPTIMAL, usage,
                                                       VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT, &ip),
              VK_SUCCESS);
    EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties(physicalDevice, VkFormat(fmt), VK_IMAGE_TYPE_3D,
                                                       VK_IMAGE_TILING_OPTIMAL, usage, 0, &ip),
              VK_SUCCESS);
    EXPECT_GT(ip.maxExtent.depth, 1u);
    for (VkImageUsageFlags bad : {VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_USAGE_STORAGE_BIT})
      EXPECT_EQ(vkGetPhysicalDeviceImageFormatProperties(physicalDevice, VkFormat(fmt), VK_IMAGE_TYPE_2D,
                                                         VK_IMAGE_TILING_OPTIMAL, bad, 0, &ip),
                VK_ERROR_FORMAT_NOT_SUPPORTED);
  }
}

// Every texel of two blocks of each BC format, fetched, against the blocks' fields decoded here; the bytes read
// back through vkCmdCopyImageToBuffer are the bytes uploaded.
TEST_F(CompressedFormatTest, EveryTexelOfEveryFormatDecodes) {
  for (const Case& c : allCases()) {
    SCOPED_TRACE(c.format);
    Tex t = upload(c.format, {8, 4, 1}, {c.blocks});
    EXPECT_EQ(readBack(t.img.image, 0, {8, 4, 1}, c.blocks.size(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL), c.blocks);
    const std::vector<Texel> got = read(t.view, nearestSampler(), 0, 32, 8, 0);
    for (int i = 0; i < 32; ++i) expectNear(got[size_t(i)], c.texel(i % 8, i / 8), c.tolerance, "fetch", i);
    destroy(t);
  }
}

// Two solid BC1 blocks, red and blue, side by side (8x4): LINEAR filtering across the block edge weighs texels of
// both; NEAREST with each address mode picks the texel the mode names; a gather at the edge returns both blocks' R.
TEST_F(CompressedFormatTest, FilteringAddressModesAndGathersReadAcrossBlocks) {
  const uint32_t zero[16] = {};
  Tex t = upload(VK_FORMAT_BC1_RGB_UNORM_BLOCK, {8, 4, 1}, {cat(bc1(0xF800, 0xF800, zero), bc1(0x001F, 0x001F, zero))});
  const Texel red{1, 0, 0, 1}, blue{0, 0, 1, 1};
  auto mix = [&](float wBlue) { return Texel{1 - wBlue, 0, wBlue, 1}; };
  VkSampler linear = sampler(VK_FILTER_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  const std::vector<Texel> coords = {{4.0f / 8, 0.5f, 0, 0},
                                     {3.75f / 8, 0.3f, 0, 0},
                                     {4.5f / 8, 0.9f, 0, 0},
                                     {0.5f / 8, 0.5f, 0, 0},
                                     {3.5f / 8, 0.1f, 0, 0}};
  std::vector<Texel> got = read(t.view, linear, 1, int(coords.size()), 0, 0, coords);
  const float tol = onVkrt() ? 1e-5f : 1.0f / 64;
  expectNear(got[0], mix(0.5f), tol, "linear", 0);
  expectNear(got[1], mix(0.25f), tol, "linear", 1);
  expectNear(got[2], mix(1.0f), tol, "linear", 2);
  expectNear(got[3], red, tol, "linear", 3);
  expectNear(got[4], red, tol, "linear", 4);
  // Gather of R at the block edge: (i0, j1), (i1, j1), (i1, j0), (i0, j0) = red, blue, blue, red.
  got = read(t.view, linear, 2, 1, 0, 0, {{4.0f / 8, 0.5f, 0, 0}});
  expectNear(got[0], Texel{1, 0, 0, 1}, 0, "gather", 0);
  vkDestroySampler(device, linear, nullptr);
  // Past the right edge (texel 8.5): REPEAT wraps to texel 0 (red), CLAMP_TO_EDGE stays on texel 7 (blue),
  // MIRRORED_REPEAT reflects to texel 7 (blue), CLAMP_TO_BORDER reads the border, MIRROR_CLAMP_TO_EDGE clamps to 7;
  // texel -0.5: MIRRORED_REPEAT and MIRROR_CLAMP_TO_EDGE read texel 0 (red).
  const struct {
    VkSamplerAddressMode mode;
    float u;
    Texel want;
  } modes[] = {
      {VK_SAMPLER_ADDRESS_MODE_REPEAT, 8.5f / 8, red},
      {VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE, 8.5f / 8, blue},
      {VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT, 8.5f / 8, blue},
      {VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT, -0.5f / 8, red},
      {VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER, 8.5f / 8, Texel{1, 1, 1, 1}},
      {VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE, 8.5f / 8, blue},
      {VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE, -0.5f / 8, red},
      {VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE, -12.5f / 8, blue},  // mirrored texel 12: clamped to 7
  };
  for (const auto& m : modes) {
    VkSampler s = sampler(VK_FILTER_NEAREST, m.mode, VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE);
    got = read(t.view, s, 1, 1, 0, 0, {{m.u, 0.5f, 0, 0}});
    expectNear(got[0], m.want, 1e-6f, "address mode", int(m.mode));
    vkDestroySampler(device, s, nullptr);
  }
  destroy(t);
}

// An 8x8 BC7 image of four mip levels: 8x8 (2x2 blocks), 4x4, 2x2 and 1x1, the last two smaller than their block.
// Each level is uploaded with its extent in texels and read back as whole blocks; texelFetch and NEAREST sampling of
// each level read its block's texels.
TEST_F(CompressedFormatTest, MipLevelsSmallerThanABlockTakeAWholeBlock) {
  std::vector<Bc7Mode6> blocks;
  std::vector<Block> levels(4);
  for (int m = 0; m < 4; ++m)
    for (int b = 0; b < (m == 0 ? 4 : 1); ++b) {
      Bc7Mode6 e{{{uint8_t(10 * m + b), uint8_t(100 + b), uint8_t(30 * m), 127},
                  {uint8_t(127 - 10 * m), uint8_t(20 * b), uint8_t(60), uint8_t(90 + m)}},
                 {uint8_t(m & 1), uint8_t(b & 1)},
                 {}};
      for (int i = 0; i < 16; ++i) e.idx[i] = uint32_t((i * (m + 3) + b) % 16);
      e.idx[0] &= 7;
      blocks.push_back(e);
      levels[size_t(m)] = cat(levels[size_t(m)], e.encode());
    }
  Tex t = upload(VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, levels);
  for (uint32_t m = 0; m < 4; ++m) {
    const uint32_t size = 8u >> m;
    EXPECT_EQ(readBack(t.img.image, m, {size, size, 1}, levels[m].size(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL),
              levels[m])
        << "level " << m;
    const std::vector<Texel> got = read(t.view, nearestSampler(), 0, int(size * size), int(size), int(m));
    for (uint32_t i = 0; i < size * size; ++i) {
      const uint32_t x = i % size, y = i / size;
      const size_t block = m == 0 ? (y / 4) * 2 + x / 4 : 3 + m;
      expectNear(got[i], blocks[block].texel(int((y % 4) * 4 + x % 4)), 2e-6f, "level texel", int(m * 100 + i));
    }
  }
  // textureLod at level 2 (2x2 texels): the texel centres (0.25, 0.75) read texels (0, 1) and (1, 1) of its block.
  const std::vector<Texel> got =
      read(t.view, nearestSampler(), 1, 2, 0, 0, {{0.25f, 0.75f, 2.0f, 0}, {0.75f, 0.75f, 2.0f, 0}});
  expectNear(got[0], blocks[5].texel(4), 2e-6f, "level 2 sample", 0);
  expectNear(got[1], blocks[5].texel(5), 2e-6f, "level 2 sample", 1);
  destroy(t);
}

// vkCmdBlitImage from a BC1 image (red | blue, 8x4) to RGBA8: 1:1 NEAREST copies each decoded texel; 2:1 LINEAR
// averages within each block.
TEST_F(CompressedFormatTest, BlitsDecodeTheSource) {
  const uint32_t zero[16] = {};
  Tex src =
      upload(VK_FORMAT_BC1_RGB_UNORM_BLOCK, {8, 4, 1}, {cat(bc1(0xF800, 0xF800, zero), bc1(0x001F, 0x001F, zero))});
  Img dst = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {8, 4, 1}, 1, 1));
  VkCommandBuffer cb = beginOneTime();
  transition(cb, src.img.image, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  toDst(cb, dst.image);
  VkImageBlit b{};
  b.srcSubresource = b.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  b.srcOffsets[1] = {8, 4, 1};
  b.dstOffsets[1] = {8, 4, 1};
  vkCmdBlitImage(cb, src.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &b, VK_FILTER_NEAREST);
  b.dstOffsets[1] = {4, 2, 1};  // 2:1 into the top left corner
  vkCmdBlitImage(cb, src.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &b, VK_FILTER_LINEAR);
  transition(cb, src.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  dstToSrc(cb, dst.image);
  submitAndWait(cb);
  const Block px = readBack(dst.image, 0, {8, 4, 1}, 8 * 4 * 4, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      const uint8_t* p = &px[size_t(y * 8 + x) * 4];
      // The 2:1 blit's texel (x, y) < (4, 2) samples the source at (2x + 1, 2y + 1): red for x < 2, blue after.
      const bool blue = (x < 4 && y < 2) ? x >= 2 : x >= 4;
      EXPECT_EQ(p[0], blue ? 0 : 255) << x << "," << y;
      EXPECT_EQ(p[1], 0) << x << "," << y;
      EXPECT_EQ(p[2], blue ? 255 : 0) << x << "," << y;
      EXPECT_EQ(p[3], 255) << x << "," << y;
    }
  destroy(dst);
  destroy(src);
}

// vkCmdCopyImage between a BC7 image (8x8: 2x2 blocks) and an R32G32B32A32_UINT image (2x2), each texel of which is a
// block: the extent is in the source's texels (8x8 from BC7, 2x2 from RGBA32UI), offsets in each side's texels.
TEST_F(CompressedFormatTest, CopiesBetweenBc7AndRgba32uiMoveWholeBlocks) {
  std::vector<Bc7Mode6> blocks;
  Block bytes;
  for (int b = 0; b < 4; ++b) {
    Bc7Mode6 e{{{uint8_t(30 * b), 5, 127, 60}, {uint8_t(127 - 20 * b), 90, 0, 127}}, {uint8_t(b & 1), 1}, {}};
    std::copy(kIdx16, kIdx16 + 16, e.idx);
    blocks.push_back(e);
    bytes = cat(bytes, e.encode());
  }
  Tex bc = upload(VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, {bytes});
  Img u = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32G32B32A32_UINT, {2, 2, 1}, 1, 1));
  Tex back = upload(VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, {Block(64, 0)});
  Tex small = upload(VK_FORMAT_BC7_UNORM_BLOCK, {4, 4, 1}, {Block(16, 0), Block(16, 0), Block(16, 0)});
  VkCommandBuffer cb = beginOneTime();
  const VkImageLayout ro = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  transition(cb, bc.img.image, ro, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  toDst(cb, u.image);
  VkImageCopy c{};
  c.srcSubresource = c.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  c.extent = {8, 8, 1};
  vkCmdCopyImage(cb, bc.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, u.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 1, &c);
  dstToSrc(cb, u.image);
  transition(cb, back.img.image, ro, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  transition(cb, small.img.image, ro, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  // RGBA32UI texel (1, 0) into the one block of small's level 0 (4x4 texels); then all four back in place.
  c.extent = {1, 1, 1};
  c.srcOffset = {1, 0, 0};
  vkCmdCopyImage(cb, u.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, small.img.image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
  c.srcOffset = {0, 0, 0};
  c.extent = {2, 2, 1};
  vkCmdCopyImage(cb, u.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, back.img.image,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
  transition(cb, bc.img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, ro);
  transition(cb, back.img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, ro);
  transition(cb, small.img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, ro);
  submitAndWait(cb);
  // The uint image's texels are the blocks, row by row.
  EXPECT_EQ(readBack(u.image, 0, {2, 2, 1}, 64, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL), bytes);
  EXPECT_EQ(readBack(back.img.image, 0, {8, 8, 1}, 64, ro), bytes);
  EXPECT_EQ(readBack(small.img.image, 0, {4, 4, 1}, 16, ro), blocks[1].encode());
  // And the copied blocks decode: texel (5, 2) of `back` is texel (1, 2) of block 1.
  const std::vector<Texel> got = read(back.view, nearestSampler(), 0, 64, 8, 0);
  for (int i = 0; i < 64; ++i) {
    const int x = i % 8, y = i / 8;
    expectNear(got[size_t(i)], blocks[size_t((y / 4) * 2 + x / 4)].texel((y % 4) * 4 + x % 4), 2e-6f, "copied", i);
  }
  destroy(small);
  destroy(back);
  destroy(u);
  destroy(bc);
}

// VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT: a BC7 image (8x8) viewed as R32G32B32A32_UINT at level 0 is a 2x2
// storage image of its blocks (imageSize in blocks); a shader loads each block and stores another, which the BC7 view
// then decodes.
TEST_F(CompressedFormatTest, BlockTexelViewCompatibleViewsAddressBlocks) {
  std::vector<Bc7Mode6> blocks;
  Block bytes;
  for (int b = 0; b < 4; ++b) {
    Bc7Mode6 e{{{uint8_t(b), 2, 3, 4}, {5, uint8_t(6 * b), 7, 8}}, {0, 1}, {}};
    std::copy(kIdx16, kIdx16 + 16, e.idx);
    blocks.push_back(e);
    bytes = cat(bytes, e.encode());
  }
  const VkImageCreateFlags flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT |
                                   VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT | VK_IMAGE_CREATE_EXTENDED_USAGE_BIT;
  Tex t = upload(VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, {bytes, Block(16, 0)}, VK_IMAGE_USAGE_STORAGE_BIT, flags);
  VkImageViewUsageCreateInfo vu{VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO};
  vu.usage = VK_IMAGE_USAGE_STORAGE_BIT;
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, &vu};
  vi.image = t.img.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = VK_FORMAT_R32G32B32A32_UINT;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView blockView = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &blockView), VK_SUCCESS);

  ComputePipeline p =
      makeComputePipeline(device, kSpv_compressed_block_view_comp, sizeof kSpv_compressed_block_view_comp,
                          {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 16);
  ASSERT_EQ(p.result, VK_SUCCESS);
  HostBuffer out = createHostBuffer(5 * 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  writeBuffer(p, 1, out);
  VkDescriptorImageInfo ii{VK_NULL_HANDLE, blockView, VK_IMAGE_LAYOUT_GENERAL};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = p.set;
  w.dstBinding = 0;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
  w.pImageInfo = &ii;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  // The replacement: block 0's words; invocation i stores them plus i in each word.
  uint32_t replacement[4];
  const Block b0 = blocks[0].encode();
  std::memcpy(replacement, b0.data(), 16);
  VkCommandBuffer cb = beginOneTime();
  VkImageMemoryBarrier ib{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  ib.srcAccessMask = VK_ACCESS_SHADER_READ_BIT;
  ib.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  ib.oldLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  ib.newLayout = VK_IMAGE_LAYOUT_GENERAL;
  ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  ib.image = t.img.image;
  ib.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 2, 0, 1};
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &ib);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 16, replacement);
  vkCmdDispatch(cb, 1, 1, 1);
  ib.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  ib.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  ib.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
  ib.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &ib);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
  submitAndWait(cb);
  const uint32_t* o = static_cast<const uint32_t*>(out.data);
  EXPECT_EQ(o[0], 2u);  // imageSize: 2x2 blocks
  EXPECT_EQ(o[1], 2u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(std::memcmp(o + 4 + 4 * i, &bytes[size_t(16 * i)], 16), 0) << "block " << i;
  // Every block now holds block 0's words plus its index: block 0 decodes as block 0 did.
  Block expect;
  for (uint32_t i = 0; i < 4; ++i) {
    uint32_t words[4];
    for (int k = 0; k < 4; ++k) words[k] = replacement[k] + i;
    expect.insert(expect.end(), reinterpret_cast<uint8_t*>(words), reinterpret_cast<uint8_t*>(words) + 16);
  }
  EXPECT_EQ(readBack(t.img.image, 0, {8, 8, 1}, 64, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL), expect);
  const std::vector<Texel> got = read(t.view, nearestSampler(), 0, 16, 4, 0);
  for (int i = 0; i < 16; ++i) expectNear(got[size_t(i)], blocks[0].texel(i), 2e-6f, "rewritten", i);
  destroy(out);
  vkDestroyPipeline(device, p.pipeline, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  vkDestroyDescriptorPool(device, p.pool, nullptr);
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
  vkDestroyImageView(device, blockView, nullptr);
  destroy(t);
}

// A 3D BC1 image of 8x4x2 texels (two slices of 2x1 blocks, uploaded in one buffer copy) blitted 1:1 into a 3D
// RGBA8 image: each slice's blocks decode in place.
TEST_F(CompressedFormatTest, ThreeDimensionalImagesHoldASliceOfBlocksPerDepth) {
  const uint32_t zero[16] = {};
  const uint16_t colours[4] = {0xF800, 0x001F, 0x07E0, 0xFFFF};  // red, blue | green, white
  Block bytes;
  for (uint16_t c : colours) bytes = cat(bytes, bc1(c, c, zero));
  VkImageCreateInfo ci = imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_BC1_RGB_UNORM_BLOCK, {8, 4, 2}, 1, 1);
  Img src = createImage(ci);
  Img dst = createImage(imageInfo(VK_IMAGE_TYPE_3D, VK_FORMAT_R8G8B8A8_UNORM, {8, 4, 2}, 1, 1));
  HostBuffer staging = createHostBuffer(bytes.size(), kXfer);
  std::memcpy(staging.data, bytes.data(), bytes.size());
  HostBuffer out = createHostBuffer(8 * 4 * 2 * 4, kXfer);
  VkCommandBuffer cb = beginOneTime();
  toDst(cb, src.image);
  toDst(cb, dst.image);
  VkBufferImageCopy r{};
  r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r.imageExtent = {8, 4, 2};
  vkCmdCopyBufferToImage(cb, staging.buffer, src.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
  dstToSrc(cb, src.image);
  VkImageBlit b{};
  b.srcSubresource = b.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  b.srcOffsets[1] = b.dstOffsets[1] = {8, 4, 2};
  vkCmdBlitImage(cb, src.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 1, &b, VK_FILTER_NEAREST);
  dstToSrc(cb, dst.image);
  vkCmdCopyImageToBuffer(cb, dst.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.buffer, 1, &r);
  submitAndWait(cb);
  const uint8_t* px = static_cast<const uint8_t*>(out.data);
  const uint8_t want[4][4] = {{255, 0, 0, 255}, {0, 0, 255, 255}, {0, 255, 0, 255}, {255, 255, 255, 255}};
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 8; ++x)
        EXPECT_EQ(std::memcmp(px + ((z * 4 + y) * 8 + x) * 4, want[z * 2 + x / 4], 4), 0) << x << "," << y << "," << z;
  destroy(out);
  destroy(staging);
  destroy(dst);
  destroy(src);
}

// The rules of compressed formats, with the validation layer off: each broken rule is reported by vkrt with its
// VUID and records nothing; the valid forms beside them (extents reaching a level's edge, row lengths of whole
// blocks) are not reported.
class CompressedFormatMisuseTest : public CompressedFormatTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = CompressedFormatTest::options();
    o.validation = false;
    return o;
  }
};

TEST_F(CompressedFormatMisuseTest, CopyRulesOfBlocksAreReported) {
  // A 12x6 BC1 image: 3x2 blocks, the bottom row partial (rows 4..5).
  const VkImageCreateInfo ci = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_BC1_RGBA_UNORM_BLOCK, {12, 6, 1}, 2, 1);
  Img img = createImage(ci);
  Img u = createImage(imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R32G32_UINT, {3, 2, 1}, 1, 1));
  HostBuffer buf = createHostBuffer(4096, kXfer);
  VkCommandBuffer cb = beginOneTime();
  toDst(cb, img.image);
  toDst(cb, u.image);
  struct BufferCase {
    uint32_t rowLength, imageHeight;
    VkOffset3D offset;
    VkExtent3D extent;
    VkDeviceSize bufferOffset;
    const char* rule;  // nullptr: valid
  };
  const BufferCase bufferCases[] = {
      {0, 0, {0, 0, 0}, {12, 6, 1}, 0, nullptr},  // the whole level, the partial row reaching its edge
      {16, 8, {4, 4, 0}, {8, 2, 1}, 8, nullptr},  // whole-block row length, edge-reaching height
      {6, 0, {0, 0, 0}, {4, 4, 1}, 0, "bufferRowLength-00203"},
      {0, 6, {0, 0, 0}, {4, 4, 1}, 0, "bufferImageHeight-00204"},
      {0, 0, {2, 0, 0}, {4, 4, 1}, 0, "pRegions-07274"},
      {0, 0, {0, 1, 0}, {4, 4, 1}, 0, "pRegions-07275"},
      {0, 0, {0, 0, 0}, {6, 4, 1}, 0, "imageExtent-00207"},
      {0, 0, {0, 0, 0}, {4, 3, 1}, 0, "imageExtent-00208"},
      {0, 0, {0, 0, 0}, {4, 4, 1}, 4, "bufferOffset-00193"},  // not a multiple of the 8-byte block
  };
  for (bool toImage : {true, false}) {
    if (!toImage) transition(cb, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    for (const BufferCase& c : bufferCases) {
      SCOPED_TRACE(c.rule ? c.rule : "valid");
      VkBufferImageCopy r{};
      r.bufferOffset = c.bufferOffset;
      r.bufferRowLength = c.rowLength;
      r.bufferImageHeight = c.imageHeight;
      r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      r.imageOffset = c.offset;
      r.imageExtent = c.extent;
      if (toImage)
        vkCmdCopyBufferToImage(cb, buf.buffer, img.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
      else
        vkCmdCopyImageToBuffer(cb, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buf.buffer, 1, &r);
      if (!c.rule) {
        EXPECT_TRUE(vkrtMessages().empty());
        continue;
      }
      const std::string vuid =
          std::string("VUID-") + (toImage ? "vkCmdCopyBufferToImage-" : "vkCmdCopyImageToBuffer-") + c.rule;
      expectVkrtMessage(vuid.c_str());
    }
    // The same rules through the copy commands 2 (their structures' VUIDs).
    VkBufferImageCopy2 r2{VK_STRUCTURE_TYPE_BUFFER_IMAGE_COPY_2};
    r2.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    r2.imageOffset = {0, 2, 0};
    r2.imageExtent = {4, 4, 1};
    if (toImage) {
      VkCopyBufferToImageInfo2 i2{VK_STRUCTURE_TYPE_COPY_BUFFER_TO_IMAGE_INFO_2};
      i2.srcBuffer = buf.buffer;
      i2.dstImage = img.image;
      i2.dstImageLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
      i2.regionCount = 1;
      i2.pRegions = &r2;
      vkCmdCopyBufferToImage2(cb, &i2);
      expectVkrtMessage("VUID-VkCopyBufferToImageInfo2-pRegions-07275");
    } else {
      VkCopyImageToBufferInfo2 i2{VK_STRUCTURE_TYPE_COPY_IMAGE_TO_BUFFER_INFO_2};
      i2.srcImage = img.image;
      i2.srcImageLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      i2.dstBuffer = buf.buffer;
      i2.regionCount = 1;
      i2.pRegions = &r2;
      vkCmdCopyImageToBuffer2(cb, &i2);
      expectVkrtMessage("VUID-VkCopyImageToBufferInfo2-pRegions-07275");
    }
  }
  // Image copies, BC1 (source, in TRANSFER_SRC) to R32G32_UINT and back: offsets in each side's texels, the extent
  // in the source's.
  struct ImageCase {
    bool fromBc;
    VkOffset3D src, dst;
    VkExtent3D extent;
    const char* rule;
  };
  const ImageCase imageCases[] = {
      {true, {0, 0, 0}, {0, 0, 0}, {12, 6, 1}, nullptr},  // the whole level into 3x2 texels
      {true, {8, 4, 0}, {2, 1, 0}, {4, 2, 1}, nullptr},   // the partial corner block
      {false, {0, 0, 0}, {0, 0, 0}, {3, 1, 1}, nullptr},  // 3x1 texels into the first row of blocks
      {false, {2, 0, 0}, {8, 0, 0}, {1, 1, 1}, nullptr},  // one texel into the last block of the row
      // A texel is a whole block of the destination, which must fit its level (the layer checks it so too).
      {false, {2, 1, 0}, {8, 4, 0}, {1, 1, 1}, "dstOffset-00150"},
      {true, {2, 0, 0}, {0, 0, 0}, {4, 4, 1}, "pRegions-07278"},
      {true, {0, 2, 0}, {0, 0, 0}, {4, 4, 1}, "pRegions-07279"},
      {true, {0, 0, 0}, {0, 0, 0}, {6, 4, 1}, "srcImage-01728"},
      {true, {0, 0, 0}, {0, 0, 0}, {4, 2, 1}, "srcImage-01729"},
      {false, {0, 0, 0}, {2, 0, 0}, {1, 1, 1}, "pRegions-07281"},
      {false, {0, 0, 0}, {0, 2, 0}, {1, 1, 1}, "pRegions-07282"},
  };
  for (const ImageCase& c : imageCases) {
    SCOPED_TRACE(c.rule ? c.rule : "valid");
    VkImageCopy r{};
    r.srcSubresource = r.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    r.srcOffset = c.src;
    r.dstOffset = c.dst;
    r.extent = c.extent;
    if (c.fromBc)
      vkCmdCopyImage(cb, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, u.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     1, &r);
    else {
      // u as the source: its layout is TRANSFER_DST; GENERAL for both directions would do as well, so use the
      // image in GENERAL through a barrier once.
      vkCmdCopyImage(cb, u.image, VK_IMAGE_LAYOUT_GENERAL, img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
    }
    if (!c.rule) {
      EXPECT_TRUE(vkrtMessages().empty());
      continue;
    }
    expectVkrtMessage((std::string("VUID-vkCmdCopyImage-") + c.rule).c_str());
  }
  // BC1 to BC1 within the image: the edge-reaching partial block of level 1 (6x3 texels: 2x1 blocks).
  VkImageCopy r{};
  r.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 1, 0, 1};
  r.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r.srcOffset = {4, 0, 0};
  r.extent = {2, 3, 1};
  vkCmdCopyImage(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
  expectVkrtMessage("VUID-vkCmdCopyImage-dstImage-01732");  // 2x3 is no whole block at (0, 0) of level 0
  r.dstOffset = {8, 0, 0};
  r.extent = {2, 3, 1};
  vkCmdCopyImage(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
  expectVkrtMessage("VUID-vkCmdCopyImage-dstImage-01732");  // x reaches 10 of 12
  VkImageCopy2 r2{VK_STRUCTURE_TYPE_IMAGE_COPY_2};
  r2.srcSubresource = r2.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r2.srcOffset = {0, 1, 0};
  r2.extent = {4, 4, 1};
  VkCopyImageInfo2 ci2{VK_STRUCTURE_TYPE_COPY_IMAGE_INFO_2};
  ci2.srcImage = img.image;
  ci2.srcImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  ci2.dstImage = u.image;
  ci2.dstImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  ci2.regionCount = 1;
  ci2.pRegions = &r2;
  vkCmdCopyImage2(cb, &ci2);
  expectVkrtMessage("VUID-VkCopyImageInfo2-pRegions-07279");

  // Nothing writes texels of a compressed image: clears and blit destinations are reported.
  const VkClearColorValue black{};
  const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, &black, 1, &all);
  expectVkrtMessage("VUID-vkCmdClearColorImage-image-00007");
  VkImageBlit b{};
  b.srcSubresource = b.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  b.srcOffsets[1] = b.dstOffsets[1] = {4, 4, 1};
  vkCmdBlitImage(cb, img.image, VK_IMAGE_LAYOUT_GENERAL, img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &b, VK_FILTER_NEAREST);
  expectVkrtMessage("VUID-vkCmdBlitImage-dstImage-02000");
  vkEndCommandBuffer(cb);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  destroy(buf);
  destroy(u);
  destroy(img);
}

TEST_F(CompressedFormatMisuseTest, CreationRulesAreReported) {
  VkImage image = VK_NULL_HANDLE;
  // BLOCK_TEXEL_VIEW_COMPATIBLE: a compressed format, with MUTABLE_FORMAT.
  VkImageCreateInfo ci = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {8, 8, 1}, 1, 1);
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT;
  EXPECT_NE(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  expectVkrtMessage("VUID-VkImageCreateInfo-flags-01572");
  ci.format = VK_FORMAT_BC7_UNORM_BLOCK;
  ci.flags = VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT;
  EXPECT_NE(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  expectVkrtMessage("VUID-VkImageCreateInfo-flags-01573");
  // A compressed color attachment, storage image or 1D image is not supported.
  for (VkImageUsageFlags bad : {VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_USAGE_STORAGE_BIT}) {
    ci = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_BC1_RGB_UNORM_BLOCK, {8, 8, 1}, 1, 1, bad);
    EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_ERROR_FORMAT_NOT_SUPPORTED);
    expectVkrtMessage("VUID-VkImageCreateInfo-imageCreateMaxMipLevels-02251");
  }
  // Nor is a block-texel-view-compatible one with attachment usage (its uncompressed views are sampled and storage
  // views only), though its storage usage is.
  ci = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, 1, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT |
             VK_IMAGE_CREATE_EXTENDED_USAGE_BIT;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_ERROR_FORMAT_NOT_SUPPORTED);
  expectVkrtMessage("VUID-VkImageCreateInfo-imageCreateMaxMipLevels-02251");
  ci.usage = VK_IMAGE_USAGE_STORAGE_BIT;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyImage(device, image, nullptr);
  ci = imageInfo(VK_IMAGE_TYPE_1D, VK_FORMAT_BC1_RGB_UNORM_BLOCK, {8, 1, 1}, 1, 1);
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_ERROR_FORMAT_NOT_SUPPORTED);
  expectVkrtMessage("VUID-VkImageCreateInfo-imageCreateMaxMipLevels-02251");

  // Views: another BC class or an uncompressed format without BLOCK_TEXEL_VIEW_COMPATIBLE; with it, an uncompressed
  // view of more than one level; the same class (BC7 SRGB) is fine.
  ci = imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_BC7_UNORM_BLOCK, {8, 8, 1}, 2, 1, VK_IMAGE_USAGE_SAMPLED_BIT | kImgXfer);
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  Img mut = createImage(ci);
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT;
  Img blockTexel = createImage(ci);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  vi.image = mut.image;
  vi.format = VK_FORMAT_BC7_SRGB_BLOCK;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyImageView(device, view, nullptr);
  for (VkFormat f : {VK_FORMAT_BC6H_UFLOAT_BLOCK, VK_FORMAT_R32G32B32A32_UINT}) {
    vi.format = f;
    EXPECT_NE(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
    expectVkrtMessage("VUID-VkImageViewCreateInfo-image-01018");
  }
  vi.image = blockTexel.image;
  vi.format = VK_FORMAT_R32G32_UINT;  // 8 bytes, not the 16-byte block
  EXPECT_NE(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  expectVkrtMessage("VUID-VkImageViewCreateInfo-image-01583");
  vi.format = VK_FORMAT_R32G32B32A32_UINT;
  vi.subresourceRange.levelCount = 2;
  EXPECT_NE(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  expectVkrtMessage("VUID-VkImageViewCreateInfo-image-07072");
  vi.subresourceRange.levelCount = 1;
  vi.subresourceRange.baseMipLevel = 1;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyImageView(device, view, nullptr);
  destroy(blockTexel);
  destroy(mut);
}

}  // namespace
}  // namespace vkrt::test
