// Sampling rules the texture CTS found broken, on the image functions directly (runtime/image_functions.cpp):
// "Border Replacement" of formats with fewer than four components (the missing ones read as Component Substitution
// gives them) and "Texel Anisotropic Filtering" (the spec's N-sample scheme along the major axis) against a
// double-precision reference written here from the spec's formulas, both sides of each path choice.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/image.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/image_view.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/sampler.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

float asFloat(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

class SamplerConformance : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    VkPhysicalDeviceFeatures features{};
    features.samplerAnisotropy = VK_TRUE;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pEnabledFeatures = &features;
    dev = createObject<Device>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, fromHandle<PhysicalDevice>(pd), dci);
    ASSERT_NE(dev, nullptr);
    ASSERT_TRUE(dev->enabled(Feature::samplerAnisotropy));
    device = toHandle(dev);
  }
  void TearDown() override {
    for (VkSampler s : samplers) vkrt_DestroySampler(device, s, nullptr);
    for (VkImageView v : views) vkrt_DestroyImageView(device, v, nullptr);
    for (VkImage i : images) vkrt_DestroyImage(device, i, nullptr);
    for (VkDeviceMemory m : memories) vkrt_FreeMemory(device, m, nullptr);
    destroyObject(dev, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  // A w x h 2D image of `format` with `levels` levels, bound to fresh memory.
  Image* makeImage(VkFormat format, uint32_t w, uint32_t h, uint32_t levels) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {w, h, 1};
    ci.mipLevels = levels;
    ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImage image;
    EXPECT_EQ(vkrt_CreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
    images.push_back(image);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    VkDeviceMemory memory;
    EXPECT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
    memories.push_back(memory);
    EXPECT_EQ(vkrt_BindImageMemory(device, image, memory, 0), VK_SUCCESS);
    return fromHandle<Image>(image);
  }
  abi::DescriptorRecord viewOf(Image* img, VkImageAspectFlags aspect) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = toHandle(img);
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = img->format;
    vi.subresourceRange = {aspect, 0, img->mipLevels, 0, 1};
    VkImageView view;
    EXPECT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
    views.push_back(view);
    abi::DescriptorRecord r{};
    r.object = static_cast<const Object*>(fromHandle<ImageView>(view));
    return r;
  }
  abi::DescriptorRecord sampler(const VkSamplerCreateInfo& ci) {
    VkSampler s = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateSampler(device, &ci, nullptr, &s), VK_SUCCESS);
    samplers.push_back(s);
    abi::DescriptorRecord r{};
    r.sampler = static_cast<const Object*>(fromHandle<Sampler>(s));
    return r;
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  Device* dev = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkDeviceMemory> memories;
  std::vector<VkSampler> samplers;
};

VkSamplerCreateInfo borderSampler(VkBorderColor color, bool unnormalized, VkFilter filter) {
  VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  ci.magFilter = ci.minFilter = filter;
  ci.addressModeU = ci.addressModeV = ci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
  ci.borderColor = color;
  ci.unnormalizedCoordinates = unnormalized;
  return ci;
}

// dEQP-VK.texture.filtering.unnormal.formats.{b10g11r11_ufloat,s8_uint,d24_unorm_s8_uint_stencil}: a border texel
// replaces only the format's components; G, B and A of a one-component format and A of a three-component one read
// 0, 0 and 1 as for any texel of those formats. Four-component formats keep the whole border color.
TEST_F(SamplerConformance, BorderReplacesOnlyTheComponentsTheFormatHas) {
  const uint32_t one = 0x3f800000u;  // 1.0f
  struct Case {
    VkFormat format;
    VkImageAspectFlags aspect;
    VkBorderColor border;
    uint32_t want[4];
  };
  const Case cases[] = {
      {VK_FORMAT_B10G11R11_UFLOAT_PACK32,
       VK_IMAGE_ASPECT_COLOR_BIT,
       VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK,
       {0, 0, 0, one}},
      {VK_FORMAT_B10G11R11_UFLOAT_PACK32,
       VK_IMAGE_ASPECT_COLOR_BIT,
       VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
       {one, one, one, one}},
      {VK_FORMAT_R8G8_UNORM, VK_IMAGE_ASPECT_COLOR_BIT, VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE, {one, one, 0, one}},
      {VK_FORMAT_S8_UINT, VK_IMAGE_ASPECT_STENCIL_BIT, VK_BORDER_COLOR_INT_OPAQUE_WHITE, {1, 0, 0, 1}},
      {VK_FORMAT_S8_UINT, VK_IMAGE_ASPECT_STENCIL_BIT, VK_BORDER_COLOR_INT_TRANSPARENT_BLACK, {0, 0, 0, 1}},
      {VK_FORMAT_D24_UNORM_S8_UINT, VK_IMAGE_ASPECT_STENCIL_BIT, VK_BORDER_COLOR_INT_OPAQUE_WHITE, {1, 0, 0, 1}},
      {VK_FORMAT_D32_SFLOAT, VK_IMAGE_ASPECT_DEPTH_BIT, VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE, {one, 0, 0, one}},
      // The other side: four components take the border color whole, alpha 0 included.
      {VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_ASPECT_COLOR_BIT, VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK, {0, 0, 0, 0}},
      {VK_FORMAT_R16G16B16A16_SFLOAT,
       VK_IMAGE_ASPECT_COLOR_BIT,
       VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE,
       {one, one, one, one}},
  };
  for (const Case& c : cases) {
    Image* img = makeImage(c.format, 4, 4, 1);
    std::memset(img->data(), 0x5a, img->mips[0].arrayPitch);  // texels inside are not the border
    const abi::DescriptorRecord view = viewOf(img, c.aspect);
    const bool integer = c.aspect == VK_IMAGE_ASPECT_STENCIL_BIT;
    for (bool unnormalized : {true, false}) {
      for (VkFilter filter : {VK_FILTER_NEAREST, VK_FILTER_LINEAR}) {
        if (integer && filter == VK_FILTER_LINEAR) continue;  // integer formats are not filtered
        const abi::DescriptorRecord smp = sampler(borderSampler(c.border, unnormalized, filter));
        // Well outside: every texel the filter reads is a border texel (unnormalized -8 texels, normalized -2).
        const float coord[4] = {unnormalized ? -8.0f : -2.0f, unnormalized ? 2.0f : 0.5f, 0, 0};
        uint32_t out[4];
        vkrt_image_sample(&view, &smp, coord, 0.0f, out);
        for (int k = 0; k < 4; ++k)
          EXPECT_EQ(out[k], c.want[k]) << "format " << c.format << " border " << c.border << " unnormalized "
                                       << unnormalized << " filter " << filter << " component " << k;
      }
    }
  }
}

// ---- Anisotropic filtering

// Texel (x, y) of level `level`: R alternates 0 / 255 by column (stripes the footprint's major axis crosses), G by
// row, B a ramp in x, A a ramp in y; levels differ (the level selection shows).
uint8_t pattern(uint32_t level, uint32_t x, uint32_t y, int c) {
  switch (c) {
    case 0: return (x + level) % 2 ? 255 : 0;
    case 1: return (y + level) % 2 ? 255 : 0;
    case 2: return uint8_t(x * 7 + level * 40);
    default: return uint8_t(y * 5 + level * 60);
  }
}

class SamplerAnisotropy : public SamplerConformance {
 protected:
  // A 32x32 RGBA8 UNorm image with `levels` levels, each filled with pattern().
  void makePatternImage(uint32_t levels) {
    img = makeImage(VK_FORMAT_R8G8B8A8_UNORM, kSize, kSize, levels);
    for (uint32_t m = 0; m < levels; ++m)
      for (uint32_t y = 0; y < img->mips[m].extent.height; ++y)
        for (uint32_t x = 0; x < img->mips[m].extent.width; ++x)
          for (int c = 0; c < 4; ++c) img->texel(m, 0, x, y, 0)[c] = pattern(m, x, y, c);
    view = viewOf(img, VK_IMAGE_ASPECT_COLOR_BIT);
  }
  abi::DescriptorRecord anisoSampler(bool enable, float maxAnisotropy) {
    VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    ci.magFilter = ci.minFilter = VK_FILTER_LINEAR;
    ci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    ci.addressModeU = ci.addressModeV = ci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    ci.anisotropyEnable = enable;
    ci.maxAnisotropy = maxAnisotropy;
    ci.maxLod = 16;
    return sampler(ci);
  }

  // The reference: bilinear filtering of `level` at normalized (u, v), clamp to edge, in double ("Texel Filtering").
  double bilinear(uint32_t level, double u, double v, int c) const {
    const int64_t w = img->mips[level].extent.width, h = img->mips[level].extent.height;
    const double fu = u * double(w) - 0.5, fv = v * double(h) - 0.5;
    const int64_t i0 = int64_t(std::floor(fu)), j0 = int64_t(std::floor(fv));
    const double a = fu - std::floor(fu), b = fv - std::floor(fv);
    auto t = [&](int64_t i, int64_t j) {
      return pattern(level, uint32_t(std::clamp<int64_t>(i, 0, w - 1)), uint32_t(std::clamp<int64_t>(j, 0, h - 1)), c) /
             255.0;
    };
    return (1 - a) * (1 - b) * t(i0, j0) + a * (1 - b) * t(i0 + 1, j0) + (1 - a) * b * t(i0, j0 + 1) +
           a * b * t(i0 + 1, j0 + 1);
  }
  // The spec's scheme: N = ceil(eta) bilinear samples at `level` along `axis` (the major axis's derivative) at
  // x - 1/2 + i / (N + 1), averaged.
  double anisotropic(uint32_t level, const float* coord, const float* axis, int n, int c) const {
    double sum = 0;
    for (int i = 1; i <= n; ++i) {
      const double t = -0.5 + double(i) / double(n + 1);
      sum += bilinear(level, coord[0] + t * axis[0], coord[1] + t * axis[1], c);
    }
    return sum / n;
  }
  static std::vector<float> floats(const uint32_t out[4]) {
    return {asFloat(out[0]), asFloat(out[1]), asFloat(out[2]), asFloat(out[3])};
  }

  static constexpr uint32_t kSize = 32;
  Image* img = nullptr;
  abi::DescriptorRecord view{};
};

// One isotropic sample of an RGBA8 UNORM view takes the fast path, whose LINEAR weights are quantized to 2^-8
// (docs/graphics-shaders.md; the 2^-subTexelPrecisionBits "Texel Filtering" allows): within 2 x 2^-8 of the exact
// bilinear value, plus float rounding. The anisotropic samples take the general path, in float.
constexpr double kFixedPointLinear = 2 * 0x1p-8 + 4e-6;

// dEQP-VK.texture.filtering_anisotropy.*: a footprint 4 texels long in x and 1 in y. Isotropic (anisotropyEnable off,
// or maxAnisotropy 1): one bilinear sample at lambda = log2(4), level 0 of a single-level image. Anisotropic: eta =
// min(4, maxAnisotropy) samples at lambda = log2(4 / eta), spread along x.
TEST_F(SamplerAnisotropy, SamplesAlongTheMajorAxisAtTheMinorAxisLevel) {
  makePatternImage(1);
  const float coord[4] = {0.43f, 0.61f, 0, 0};
  const float ddx[4] = {4.0f / kSize, 0, 0, 0}, ddy[4] = {0, 1.0f / kSize, 0, 0};
  uint32_t iso[4], off[4], one[4], four[4], sixteen[4], two[4];
  const abi::DescriptorRecord disabled = anisoSampler(false, 16), max1 = anisoSampler(true, 1);
  const abi::DescriptorRecord max2 = anisoSampler(true, 2), max4 = anisoSampler(true, 4),
                              max16 = anisoSampler(true, 16);
  vkrt_image_sample_grad(&view, &disabled, coord, ddx, ddy, NAN, off);
  vkrt_image_sample_grad(&view, &max1, coord, ddx, ddy, NAN, one);
  vkrt_image_sample_grad(&view, &max2, coord, ddx, ddy, NAN, two);
  vkrt_image_sample_grad(&view, &max4, coord, ddx, ddy, NAN, four);
  vkrt_image_sample_grad(&view, &max16, coord, ddx, ddy, NAN, sixteen);
  vkrt_image_sample(&view, &disabled, coord, 2.0f, iso);
  for (int c = 0; c < 4; ++c) {
    SCOPED_TRACE(c);
    // The isotropic side: the one bilinear sample, whatever maxAnisotropy says when anisotropy is off or 1.
    EXPECT_NEAR(asFloat(off[c]), bilinear(0, coord[0], coord[1], c), kFixedPointLinear);
    EXPECT_EQ(off[c], iso[c]);
    EXPECT_EQ(one[c], off[c]);
    // The anisotropic side: eta = 2 (maxAnisotropy) and 4 (the footprint's ratio, also with maxAnisotropy 16).
    EXPECT_NEAR(asFloat(two[c]), anisotropic(0, coord, ddx, 2, c), 2e-6);
    EXPECT_NEAR(asFloat(four[c]), anisotropic(0, coord, ddx, 4, c), 2e-6);
    EXPECT_EQ(sixteen[c], four[c]);
  }
  // The stripes across the major axis average out: the one sample reads a stripe, the four samples a mix.
  EXPECT_GT(std::fabs(asFloat(four[0]) - asFloat(off[0])), 0.1f);
}

// The major axis in y, a mipmapped image: rho = (2, 8) texels, maxAnisotropy 4: eta 4, lambda = log2(8 / 4) = 1,
// so four samples of level 1 along ddy (mipmapMode NEAREST); the isotropic sample reads level 3 (log2(8)).
TEST_F(SamplerAnisotropy, MajorAxisInYAndTheLevelOfTheMinorAxis) {
  makePatternImage(4);
  const float coord[4] = {0.37f, 0.52f, 0, 0};
  const float ddx[4] = {2.0f / kSize, 0, 0, 0}, ddy[4] = {1.0f / kSize, 8.0f / kSize, 0, 0};
  // |ddy| = sqrt(1 + 64) texels: eta = sqrt(65) / 2 clamped to 4, lambda = log2(sqrt(65) / 4) = 1.01: level 1.
  const abi::DescriptorRecord on = anisoSampler(true, 4), offS = anisoSampler(false, 4);
  uint32_t a[4], b[4];
  vkrt_image_sample_grad(&view, &on, coord, ddx, ddy, NAN, a);
  vkrt_image_sample_grad(&view, &offS, coord, ddx, ddy, NAN, b);
  for (int c = 0; c < 4; ++c) {
    SCOPED_TRACE(c);
    EXPECT_NEAR(asFloat(a[c]), anisotropic(1, coord, ddy, 4, c), 2e-6);
    EXPECT_NEAR(asFloat(b[c]), bilinear(3, coord[0], coord[1], c),
                kFixedPointLinear);  // log2(sqrt(65)) = 3.01: level 3
  }
  // A shader bias moves the anisotropic samples' level as it moves the isotropic one's: +1 -> level 2.
  vkrt_image_sample_grad(&view, &on, coord, ddx, ddy, 1.0f, a);
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(asFloat(a[c]), anisotropic(2, coord, ddy, 4, c), 2e-6) << c;
}

// Equal derivatives (a round footprint, eta = 1) and zero derivatives (a point) stay isotropic with anisotropy on:
// the same words as the sampler without it.
TEST_F(SamplerAnisotropy, IsotropicFootprintsSampleOnce) {
  makePatternImage(4);
  const float coord[4] = {0.71f, 0.29f, 0, 0};
  const float round[2][4] = {{3.0f / kSize, 0, 0, 0}, {0, 3.0f / kSize, 0, 0}};
  const float zero[4] = {0, 0, 0, 0};
  const abi::DescriptorRecord on = anisoSampler(true, 16), offS = anisoSampler(false, 1);
  uint32_t a[4], b[4];
  vkrt_image_sample_grad(&view, &on, coord, round[0], round[1], NAN, a);
  vkrt_image_sample_grad(&view, &offS, coord, round[0], round[1], NAN, b);
  EXPECT_EQ(floats(a), floats(b));
  vkrt_image_sample_grad(&view, &on, coord, zero, zero, NAN, a);
  vkrt_image_sample_grad(&view, &offS, coord, zero, zero, NAN, b);
  EXPECT_EQ(floats(a), floats(b));
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(asFloat(a[c]), bilinear(0, coord[0], coord[1], c), kFixedPointLinear) << c;
}

}  // namespace
}  // namespace vkrt
