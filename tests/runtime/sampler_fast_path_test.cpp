// The 2D sampler's fast path (runtime/image_functions.cpp, fastSampling: 8-bit RGBA / BGRA UNorm and sRGB views,
// NEAREST / LINEAR, REPEAT / CLAMP_TO_EDGE, trilinear mipmaps) against an independent double-precision reference
// of "Texel Filtering" and against the generic path (the ConstOffset form with a zero offset, which the fast path
// leaves to filterLevel), at coordinates inside, outside and on the texel boundaries of a non-power-of-two image;
// the quad entry point (vkrt_image_sample_grad_quad) against four vkrt_image_sample_grad calls, on both paths; the
// level of detail's log2 against the exact one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/device.hpp"
#include "runtime/image.hpp"
#include "runtime/image_functions.hpp"
#include "runtime/image_view.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/quad_sampling.hpp"
#include "runtime/sampler.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

class SamplerFastPath : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    VkPhysicalDeviceFeatures features{};
    features.samplerAnisotropy = VK_TRUE;  // the anisotropic quad case
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pEnabledFeatures = &features;
    dev = createObject<Device>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, fromHandle<PhysicalDevice>(pd), dci);
    ASSERT_NE(dev, nullptr);
    device = toHandle(dev);
  }
  void TearDown() override {
    for (VkSampler s : samplers) vkrt_DestroySampler(device, s, nullptr);
    if (view) vkrt_DestroyImageView(device, view, nullptr);
    if (image) vkrt_DestroyImage(device, image, nullptr);
    if (memory) vkrt_FreeMemory(device, memory, nullptr);
    destroyObject(dev, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  // A 5x3 image with 3 levels (5x3, 2x1, 1x1) of `format`, every byte pseudo-random, and a 2D view of it; or
  // width x height with `levels` levels, `fill` giving each level's bytes.
  void makeImage(VkFormat format, uint32_t width = 5, uint32_t height = 3, uint32_t levels = 3,
                 int (*fill)(uint32_t level) = nullptr) {
    createImage(format, width, height, levels, 1, 12345, fill);
    if (HasFatalFailure()) return;
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, levels, 0, 1};
    ASSERT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
    imageRecord.object = static_cast<const Object*>(fromHandle<ImageView>(view));
  }
  // `image`: width x height, `levels` levels and `layers` layers of `format` in memory of its own, every byte
  // pseudo-random from `seed` (level by level, layer by layer), or `fill`'s value for its level.
  void createImage(VkFormat format, uint32_t width, uint32_t height, uint32_t levels, uint32_t layers, uint32_t seed,
                   int (*fill)(uint32_t level) = nullptr) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {width, height, 1};
    ci.mipLevels = levels;
    ci.arrayLayers = layers;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
    ASSERT_EQ(vkrt_CreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    ASSERT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
    ASSERT_EQ(vkrt_BindImageMemory(device, image, memory, 0), VK_SUCCESS);
    Image* img = fromHandle<Image>(image);
    for (uint32_t m = 0; m < levels; ++m)
      for (uint32_t layer = 0; layer < layers; ++layer)
        for (uint32_t y = 0; y < img->mips[m].extent.height; ++y)
          for (uint32_t x = 0; x < img->mips[m].extent.width; ++x)
            for (int c = 0; c < 4; ++c) {
              seed = seed * 1664525u + 1013904223u;
              img->texel(m, layer, x, y, 0)[c] = uint8_t(fill ? fill(m) : int(seed >> 24));
            }
  }

  abi::DescriptorRecord makeSampler(VkFilter filter, VkSamplerMipmapMode mip, VkSamplerAddressMode mode,
                                    float mipLodBias = 0.0f, float maxAnisotropy = 0.0f) {
    VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    ci.anisotropyEnable = maxAnisotropy > 0.0f;
    ci.maxAnisotropy = maxAnisotropy;
    ci.magFilter = ci.minFilter = filter;
    ci.mipmapMode = mip;
    ci.addressModeU = ci.addressModeV = ci.addressModeW = mode;
    ci.mipLodBias = mipLodBias;
    ci.maxLod = 16;
    VkSampler s = VK_NULL_HANDLE;
    EXPECT_EQ(vkrt_CreateSampler(device, &ci, nullptr, &s), VK_SUCCESS);
    samplers.push_back(s);
    abi::DescriptorRecord r{};
    r.sampler = static_cast<const Object*>(fromHandle<Sampler>(s));
    return r;
  }

  // The reference: "Texel Filtering" in double from the stored bytes (sRGB by the spec's EOTF, before filtering).
  double texelValue(uint32_t level, int64_t i, int64_t j, int c, bool srgb, bool bgr) {
    const Image* img = fromHandle<Image>(image);
    const int stored = bgr && c < 3 ? 2 - c : c;
    const double v = img->texel(level, 0, uint32_t(i), uint32_t(j), 0)[stored] / 255.0;
    if (!srgb || c == 3) return v;
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  }
  static int64_t address(VkSamplerAddressMode mode, int64_t i, int64_t size) {
    if (mode == VK_SAMPLER_ADDRESS_MODE_REPEAT) return ((i % size) + size) % size;
    return std::clamp<int64_t>(i, 0, size - 1);
  }
  double filterLevel(uint32_t level, VkFilter filter, VkSamplerAddressMode mode, const float* coord, int c, bool srgb,
                     bool bgr) {
    const Image* img = fromHandle<Image>(image);
    const int64_t w = img->mips[level].extent.width, h = img->mips[level].extent.height;
    const double u = double(coord[0]) * double(w), v = double(coord[1]) * double(h);
    if (filter == VK_FILTER_NEAREST)
      return texelValue(level, address(mode, int64_t(std::floor(u)), w), address(mode, int64_t(std::floor(v)), h), c,
                        srgb, bgr);
    const double fu = u - 0.5, fv = v - 0.5, a = fu - std::floor(fu), b = fv - std::floor(fv);
    const int64_t i0 = int64_t(std::floor(fu)), j0 = int64_t(std::floor(fv));
    auto t = [&](int64_t i, int64_t j) {
      return texelValue(level, address(mode, i, w), address(mode, j, h), c, srgb, bgr);
    };
    return (1 - a) * (1 - b) * t(i0, j0) + a * (1 - b) * t(i0 + 1, j0) + (1 - a) * b * t(i0, j0 + 1) +
           a * b * t(i0 + 1, j0 + 1);
  }
  // Level selection of an explicit LOD ("Image Level(s) Selection"): lod within [0, 2], nearest or linear.
  double reference(VkFilter filter, VkSamplerMipmapMode mip, VkSamplerAddressMode mode, const float* coord, float lod,
                   int c, bool srgb, bool bgr) {
    const VkFilter f = filter;  // magFilter == minFilter in these samplers
    const double d = std::clamp(double(lod), 0.0, 2.0);
    if (mip == VK_SAMPLER_MIPMAP_MODE_NEAREST || d == std::floor(d))
      return filterLevel(uint32_t(std::ceil(d + 0.5) - 1), f, mode, coord, c, srgb, bgr);
    const uint32_t lo = uint32_t(std::floor(d)), hi = std::min(lo + 1, 2u);
    const double t = d - std::floor(d);
    return filterLevel(lo, f, mode, coord, c, srgb, bgr) * (1 - t) + filterLevel(hi, f, mode, coord, c, srgb, bgr) * t;
  }

  void compareAll(VkFormat format) {
    makeImage(format);
    const bool srgb = format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_R8G8B8A8_SRGB;
    const bool bgr = format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_B8G8R8A8_UNORM;
    // Inside, outside (negative, past 1, several periods), on texel boundaries and centres (of 5 and 3 texels), a
    // tiny negative coordinate (its fraction rounds to 1) and a large one.
    const float coords[][2] = {{0.5f, 0.5f},       {0.13f, 0.77f},   {-0.31f, 1.42f},      {2.6f, -3.9f},
                               {0.2f, 1.0f / 3},   {0.1f, 1.0f / 6}, {0.0f, 0.0f},         {1.0f, 1.0f},
                               {-1e-30f, -1e-30f}, {0.999f, 0.001f}, {1234.567f, -987.25f}};
    const float lods[] = {-1.0f, 0.0f, 0.3f, 1.0f, 1.5f, 1.99f, 7.0f};
    const int32_t zero[4] = {0, 0, 0, 0};
    for (VkFilter filter : {VK_FILTER_NEAREST, VK_FILTER_LINEAR})
      for (VkSamplerMipmapMode mip : {VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR})
        for (VkSamplerAddressMode mode : {VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE}) {
          const abi::DescriptorRecord smp = makeSampler(filter, mip, mode);
          for (const auto& xy : coords)
            for (float lod : lods) {
              const float coord[4] = {xy[0], xy[1], 0, 0};
              uint32_t fast[4], generic[4];
              vkrt_image_sample(&imageRecord, &smp, coord, lod, fast);
              vkrt_image_sample_offset(&imageRecord, &smp, coord, lod, zero, generic);
              for (int c = 0; c < 4; ++c) {
                float f, g;
                std::memcpy(&f, &fast[c], 4);
                std::memcpy(&g, &generic[c], 4);
                const double e = reference(filter, mip, mode, coord, lod, c, srgb, bgr);
                const std::string where = "format " + std::to_string(format) + " filter " + std::to_string(filter) +
                                          " mip " + std::to_string(mip) + " mode " + std::to_string(mode) + " coord " +
                                          std::to_string(xy[0]) + "," + std::to_string(xy[1]) + " lod " +
                                          std::to_string(lod) + " c " + std::to_string(c);
                // The fast path's LINEAR weights are quantized to 2^-8 (kSubTexelBits: the 2^-subTexelPrecisionBits
                // "Texel Filtering" allows, physical_device.cpp): less than 2^-8 of the largest texel difference (1)
                // per axis from the exact weights, plus a few ulp of 1 of float sums (the sRGB reference uses the
                // EOTF in double, the image functions their float table: 1e-6 more). NEAREST reads the same texel:
                // ulps only.
                const double tolerance = filter == VK_FILTER_LINEAR ? 2 * 0x1p-8 + 4e-6 : 4e-6;
                EXPECT_NEAR(f, e, tolerance) << where;
                EXPECT_NEAR(f, g, tolerance) << where;
              }
            }
        }
  }

  void compareQuad(VkFormat format, float maxAnisotropy = 0.0f);
  void compareQuadLanes(VkFormat format);
  void compareLod(VkFormat format);

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  Device* dev = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  std::vector<VkSampler> samplers;
  abi::DescriptorRecord imageRecord{};
};

// vkrt_image_sample_grad_quad samples each active lane exactly as vkrt_image_sample_grad (bit for bit) and leaves the
// others 0, on the fast path (RGBA8 UNorm, BGRA8 sRGB with REPEAT / CLAMP_TO_EDGE) and off it (SNorm, a border,
// NaN and huge coordinates, zero and NaN derivatives), with and without Bias.
void SamplerFastPath::compareQuad(VkFormat format, float maxAnisotropy) {
  makeImage(format);
  const float coords[][2] = {{0.5f, 0.5f},     {0.13f, 0.77f},  {-0.31f, 1.42f}, {2.6f, -3.9f},
                             {0.2f, 1.0f / 3}, {1.0f, 1.0f},    {NAN, 0.5f},     {1234.567f, -987.25f},
                             {3e7f, 0.25f},    {-1e-30f, 0.6f}, {0.37f, 0.41f},  {0.9f, 0.1f}};
  const float derivs[][2] = {{0.1f, 0.0f}, {0.0f, 0.0f}, {0.7f, -0.3f}, {1e-3f, 2e-3f}, {NAN, 0.1f}, {4.0f, 0.5f}};
  for (VkFilter filter : {VK_FILTER_NEAREST, VK_FILTER_LINEAR})
    for (VkSamplerMipmapMode mip : {VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR})
      for (VkSamplerAddressMode mode : {VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE,
                                        VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER})
        for (float samplerBias : {0.0f, 0.6f}) {
          const abi::DescriptorRecord smp = makeSampler(filter, mip, mode, samplerBias, maxAnisotropy);
          const size_t nc = sizeof(coords) / sizeof(coords[0]), nd = sizeof(derivs) / sizeof(derivs[0]);
          for (size_t first = 0; first < nc * nd; first += 3)
            for (uint32_t lanes : {0xfu, 0x6u, 0x0u})
              for (float bias : {NAN, -0.4f, 1.3f}) {
                float coord[16] = {}, ddx[16] = {}, ddy[16] = {}, biases[4];
                for (unsigned l = 0; l < 4; ++l) {
                  const size_t k = (first + l * 5) % (nc * nd);
                  const float* c = coords[k % nc];
                  const float* d = derivs[k / nc];
                  coord[l] = c[0], coord[4 + l] = c[1];
                  ddx[l] = d[0], ddx[4 + l] = d[1] * 0.5f, ddy[l] = -d[1], ddy[4 + l] = d[0] * 1.5f;
                  biases[l] = l == 2 ? NAN : bias;  // Bias absent in one lane
                }
                uint32_t quad[16];
                std::memset(quad, 0xcd, sizeof(quad));
                vkrt_image_sample_grad_quad(&imageRecord, &smp, coord, ddx, ddy, biases, lanes, quad);
                for (unsigned l = 0; l < 4; ++l) {
                  const float c[4] = {coord[l], coord[4 + l], 0, 0}, dx[4] = {ddx[l], ddx[4 + l], 0, 0},
                              dy[4] = {ddy[l], ddy[4 + l], 0, 0};
                  uint32_t one[4] = {0, 0, 0, 0};
                  if (lanes >> l & 1) vkrt_image_sample_grad(&imageRecord, &smp, c, dx, dy, biases[l], one);
                  for (unsigned k = 0; k < 4; ++k)
                    EXPECT_EQ(quad[4 * k + l], one[k])
                        << "format " << format << " filter " << filter << " mip " << mip << " mode " << mode << " lane "
                        << l << " lanes " << lanes << " component " << k << " coord " << c[0] << "," << c[1] << " ddx "
                        << dx[0] << "," << dx[1] << " ddy " << dy[0] << "," << dy[1];
                }
              }
        }
}

TEST_F(SamplerFastPath, QuadSamplingMatchesPerLaneSamplingRgba8Unorm) { compareQuad(VK_FORMAT_R8G8B8A8_UNORM); }
TEST_F(SamplerFastPath, QuadSamplingMatchesPerLaneSamplingBgra8Srgb) { compareQuad(VK_FORMAT_B8G8R8A8_SRGB); }
TEST_F(SamplerFastPath, QuadSamplingMatchesPerLaneSamplingOffTheFastPath) { compareQuad(VK_FORMAT_R8G8B8A8_SNORM); }
// With anisotropyEnable each lane takes its own footprint's filter (sampleAnisotropic where the ratio exceeds 1), as
// vkrt_image_sample_grad does: the quad call of fragment shaders must not sample such a sampler isotropically.
TEST_F(SamplerFastPath, QuadSamplingMatchesPerLaneSamplingAnisotropic) { compareQuad(VK_FORMAT_R8G8B8A8_UNORM, 16.0f); }

// The quad call's vector path (runtime/quad_sampling.cpp, taken where the view's and the sampler's records say so:
// asserted) against four vkrt_image_sample_grad calls, bit for bit, where its lanes differ from each other: each
// lane at its own level (derivatives from 1/64 to 64 texels, the sampler's minLod / maxLod clamps and bias), with
// its own filter (magFilter and minFilter differ), in its own layer of a 2D array view (the layer coordinate
// rounded and clamped), with and without a component mapping, beside lanes the vector path leaves to the generic
// path (NaN and huge coordinates, NaN derivatives), on a 37x23 image of 6 levels and 3 layers in the four 8-bit
// formats.
void SamplerFastPath::compareQuadLanes(VkFormat format) {
  createImage(format, 37, 23, 6, 3, 777);
  if (HasFatalFailure()) return;
  // Views of levels 1-5 and layers 1-2 (the records' base level and layer), one with a component mapping.
  VkImageView views[2] = {};
  for (int k = 0; k < 2; ++k) {
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = image;
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
    vi.format = format;
    if (k)
      vi.components = {VK_COMPONENT_SWIZZLE_B, VK_COMPONENT_SWIZZLE_ONE, VK_COMPONENT_SWIZZLE_R,
                       VK_COMPONENT_SWIZZLE_G};
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 1, 5, 1, 2};
    ASSERT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &views[k]), VK_SUCCESS);
    ASSERT_TRUE(fromHandle<ImageView>(views[k])->quad.fast);
  }
  const float coords[][3] = {{0.5f, 0.5f, 0.0f},   {0.13f, 0.77f, 1.0f},   {-0.31f, 1.42f, 0.4f},
                             {2.6f, -3.9f, 1.6f},  {0.2f, 1.0f / 3, -2.f}, {1.0f, 1.0f, 7.0f},
                             {NAN, 0.5f, 0.0f},    {0.5f, 3e7f, 1.0f},     {-1e-30f, 0.6f, 0.5f},
                             {0.37f, 0.41f, 1.5f}, {0.9f, 0.1f, 2.5f},     {0.031f, 0.97f, 1.0f}};
  const float derivs[][2] = {{1.0f / 64, 0.0f}, {0.02f, 0.3f}, {0.0f, 0.0f},  {0.7f, -0.3f},
                             {NAN, 0.1f},       {4.0f, 0.5f},  {0.05f, 0.05f}};
  const size_t nc = sizeof(coords) / sizeof(coords[0]), nd = sizeof(derivs) / sizeof(derivs[0]);
  size_t compared = 0;
  for (VkFilter mag : {VK_FILTER_NEAREST, VK_FILTER_LINEAR})
    for (VkFilter min : {VK_FILTER_NEAREST, VK_FILTER_LINEAR})
      for (VkSamplerMipmapMode mip : {VK_SAMPLER_MIPMAP_MODE_NEAREST, VK_SAMPLER_MIPMAP_MODE_LINEAR})
        for (VkSamplerAddressMode modeU : {VK_SAMPLER_ADDRESS_MODE_REPEAT, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE})
          for (int clampLods = 0; clampLods < 2; ++clampLods) {
            VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
            si.magFilter = mag;
            si.minFilter = min;
            si.mipmapMode = mip;
            si.addressModeU = modeU;
            si.addressModeV = modeU == VK_SAMPLER_ADDRESS_MODE_REPEAT ? VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE
                                                                      : VK_SAMPLER_ADDRESS_MODE_REPEAT;
            si.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
            si.mipLodBias = clampLods ? -0.35f : 0.0f;
            si.minLod = clampLods ? 0.5f : 0.0f;
            si.maxLod = clampLods ? 3.25f : 16.0f;
            VkSampler sampler = VK_NULL_HANDLE;
            ASSERT_EQ(vkrt_CreateSampler(device, &si, nullptr, &sampler), VK_SUCCESS);
            samplers.push_back(sampler);
            ASSERT_TRUE(fromHandle<Sampler>(sampler)->quad.fast);
            abi::DescriptorRecord smp{};
            smp.sampler = static_cast<const Object*>(fromHandle<Sampler>(sampler));
            for (VkImageView view : views) {
              abi::DescriptorRecord rec{};
              rec.object = static_cast<const Object*>(fromHandle<ImageView>(view));
              SCOPED_TRACE(::testing::Message()
                           << "format " << format << " mag " << mag << " min " << min << " mip " << mip << " modeU "
                           << modeU << " clampLods " << clampLods << " swizzled " << (view == views[1]));
              // One quad call against each of its lanes' own calls.
              auto compareQuad = [&](const float* coord, const float* ddx, const float* ddy, const float* biases,
                                     uint32_t lanes) {
                uint32_t quad[16];
                std::memset(quad, 0xcd, sizeof(quad));
                vkrt_image_sample_grad_quad(&rec, &smp, coord, ddx, ddy, biases, lanes, quad);
                for (unsigned l = 0; l < 4; ++l) {
                  const float c[4] = {coord[l], coord[4 + l], coord[8 + l], 0}, dx[4] = {ddx[l], ddx[4 + l], 0, 0},
                              dy[4] = {ddy[l], ddy[4 + l], 0, 0};
                  uint32_t one[4] = {0, 0, 0, 0};
                  if (lanes >> l & 1) vkrt_image_sample_grad(&rec, &smp, c, dx, dy, biases[l], one);
                  for (unsigned k = 0; k < 4; ++k)
                    EXPECT_EQ(quad[4 * k + l], one[k])
                        << "lane " << l << " lanes " << lanes << " component " << k << " coord " << c[0] << "," << c[1]
                        << "," << c[2] << " ddx " << dx[0] << "," << dx[1] << " ddy " << dy[0] << "," << dy[1];
                  ++compared;
                }
              };
              for (size_t first = 0; first < nc * nd; ++first)
                for (uint32_t lanes : {0xfu, 0xbu, 0x4u}) {
                  float coord[16] = {}, ddx[16] = {}, ddy[16] = {}, biases[4];
                  for (unsigned l = 0; l < 4; ++l) {
                    const size_t k = (first + l * 11) % (nc * nd);
                    const float* c = coords[k % nc];
                    const float* d = derivs[(k / nc + l) % nd];
                    coord[l] = c[0], coord[4 + l] = c[1], coord[8 + l] = c[2];
                    ddx[l] = d[0], ddx[4 + l] = d[1] * 0.5f, ddy[l] = -d[1], ddy[4 + l] = d[0] * (0.5f + l);
                    biases[l] = l == 1 ? NAN : 0.25f * float(l) - 0.6f;
                  }
                  compareQuad(coord, ddx, ddy, biases, lanes);
                }
              // Quads as a fragment shader's are: neighbouring coordinates and one derivative, so that the lanes
              // share their level(s) (the vector path then reads each level's record once, quad_sampling_kernels.inc
              // `grouped`; UNorm views take sampleQuadUniform's integer filter), in one layer or with lane 3 in
              // another (not grouped), and with lanes left out or refused (their levels do not count).
              for (size_t k = 0; k < nc * nd; ++k)
                for (int variant = 0; variant < 3; ++variant) {
                  const float* c = coords[k % nc];
                  const float* d = derivs[k / nc];
                  float coord[16] = {}, ddx[16] = {}, ddy[16] = {}, biases[4];
                  for (unsigned l = 0; l < 4; ++l) {
                    coord[l] = c[0] + float(l & 1) * d[0];
                    coord[4 + l] = c[1] + float(l >> 1) * d[1];
                    coord[8 + l] = variant == 1 && l == 3 ? c[2] + 1 : c[2];
                    ddx[l] = d[0], ddx[4 + l] = 0.25f * d[1], ddy[l] = -0.5f * d[0], ddy[4 + l] = d[1];
                    biases[l] = 0.1f;
                  }
                  if (variant == 2) coord[1] = NAN;  // lane 1 refused
                  compareQuad(coord, ddx, ddy, biases, variant == 2 ? 0xdu : 0xfu);
                }
            }
          }
  EXPECT_EQ(compared, size_t(2 * 2 * 2 * 2 * 2 * 2) * nc * nd * (3 + 3) * 4);
  for (VkImageView v : views) vkrt_DestroyImageView(device, v, nullptr);
}

// The quad path's two copies (quad_sampling.cpp: the baseline target's and AVX2's), each against the per-lane path
// (baseline code): the same bits whatever the CPU runs. The AVX2 copy only where the CPU has it.
void eachQuadIsa(const std::function<void()>& compare) {
  const QuadIsa before = quadSamplingIsa();
  for (QuadIsa isa : {QuadIsa::Baseline, QuadIsa::Avx2}) {
    if (!setQuadSamplingIsa(isa)) {
      EXPECT_FALSE(__builtin_cpu_supports("avx2")) << "AVX2 refused on a CPU that has it";
      continue;
    }
    SCOPED_TRACE(isa == QuadIsa::Avx2 ? "the AVX2 copy" : "the baseline copy");
    compare();
  }
  setQuadSamplingIsa(before);
}

TEST_F(SamplerFastPath, QuadVectorPathMatchesPerLaneSamplingRgba8Unorm) {
  eachQuadIsa([&] { compareQuadLanes(VK_FORMAT_R8G8B8A8_UNORM); });
}
TEST_F(SamplerFastPath, QuadVectorPathMatchesPerLaneSamplingBgra8Unorm) {
  eachQuadIsa([&] { compareQuadLanes(VK_FORMAT_B8G8R8A8_UNORM); });
}
TEST_F(SamplerFastPath, QuadVectorPathMatchesPerLaneSamplingRgba8Srgb) {
  eachQuadIsa([&] { compareQuadLanes(VK_FORMAT_R8G8B8A8_SRGB); });
}
TEST_F(SamplerFastPath, QuadVectorPathMatchesPerLaneSamplingBgra8Srgb) {
  eachQuadIsa([&] { compareQuadLanes(VK_FORMAT_B8G8R8A8_SRGB); });
}
TEST_F(SamplerFastPath, TheQuadPathRunsTheAvx2CopyWhereTheCpuHasIt) {
  // VKRT_QUAD_ISA=baseline (tools/test.sh's instruction-set matrix) keeps the baseline copy.
  const char* isa = std::getenv("VKRT_QUAD_ISA");
  const bool baseline = isa && std::string(isa) == "baseline";
  EXPECT_EQ(quadSamplingIsa(), __builtin_cpu_supports("avx2") && !baseline ? QuadIsa::Avx2 : QuadIsa::Baseline);
}

// The records hold fastSampling's decision: the vector path for the 8-bit RGBA / BGRA views and the isotropic
// samplers of its filters and address modes, the generic path for the rest.
TEST_F(SamplerFastPath, QuadRecordsTakeOnlyTheFastPathsCase) {
  makeImage(VK_FORMAT_R8G8B8A8_SNORM);
  EXPECT_FALSE(fromHandle<ImageView>(view)->quad.fast);
  vkrt_DestroyImageView(device, view, nullptr);
  vkrt_DestroyImage(device, image, nullptr);
  vkrt_FreeMemory(device, memory, nullptr);
  view = VK_NULL_HANDLE, image = VK_NULL_HANDLE, memory = VK_NULL_HANDLE;
  makeImage(VK_FORMAT_B8G8R8A8_SRGB);
  const QuadView& q = fromHandle<ImageView>(view)->quad;
  EXPECT_TRUE(q.fast);
  EXPECT_TRUE(q.srgb && q.bgr && q.identity && !q.arrayed);
  EXPECT_EQ(q.levelCount, 3u);
  EXPECT_EQ(q.levels[1].width, 2);
  EXPECT_EQ(q.levels[1].height, 1);
  auto quadSampler = [&](const abi::DescriptorRecord& r) { return recordObject<Sampler>(r.sampler)->quad; };
  EXPECT_TRUE(
      quadSampler(makeSampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT)).fast);
  EXPECT_FALSE(
      quadSampler(makeSampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER))
          .fast);
  EXPECT_FALSE(quadSampler(makeSampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT,
                                       0.0f, 4.0f))
                   .fast);  // anisotropyEnable
}

// The level of detail of the gradient forms (lodLog2 rather than the C library's log2): levels alternately 0 and 1
// everywhere, so a LINEAR mipmap returns the fraction of lambda = log2(rho) ("Level-of-Detail Operation") or one
// minus it; against log2 in double, on the fast path (RGBA8) and the generic one (the ConstOffset form, and SNorm).
void SamplerFastPath::compareLod(VkFormat format) {
  makeImage(format, 1024, 1024, 11, [](uint32_t level) { return level % 2 ? 127 : 0; });
  const double top = format == VK_FORMAT_R8G8B8A8_SNORM ? 1.0 : 127.0 / 255.0;  // level 1's value
  const abi::DescriptorRecord smp =
      makeSampler(VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR, VK_SAMPLER_ADDRESS_MODE_REPEAT);
  const int32_t zero[4] = {0, 0, 0, 0};
  for (double rho = 1.0; rho < 1000.0; rho *= 1.0137) {
    const float coord[4] = {0.3f, 0.6f, 0, 0};
    const float dx[4] = {float(rho / 1024.0), 0, 0, 0}, dy[4] = {0, float(rho / 2048.0), 0, 0};
    const double lambda = std::log2(double(dx[0]) * 1024.0);
    const double frac = lambda - std::floor(lambda);
    const double expected = (int(std::floor(lambda)) % 2 ? 1.0 - frac : frac) * top;
    uint32_t fast[4], generic[4];
    vkrt_image_sample_grad(&imageRecord, &smp, coord, dx, dy, NAN, fast);
    vkrt_image_sample_grad_offset(&imageRecord, &smp, coord, dx, dy, NAN, zero, generic);
    float f, g;
    std::memcpy(&f, &fast[0], 4);
    std::memcpy(&g, &generic[0], 4);
    // lambda in float (an ulp of 8 is 1e-6) and the float blend: 2e-6.
    EXPECT_NEAR(f, expected, 2e-6) << "rho " << rho;
    EXPECT_NEAR(g, expected, 2e-6) << "rho " << rho;
  }
  // Powers of two give whole levels (no share of the next).
  for (int k = 0; k < 10; ++k) {
    const float coord[4] = {0.3f, 0.6f, 0, 0};
    const float dx[4] = {std::ldexp(1.0f, k - 10), 0, 0, 0}, dy[4] = {0, 0, 0, 0};
    uint32_t out[4];
    vkrt_image_sample_grad(&imageRecord, &smp, coord, dx, dy, NAN, out);
    float f;
    std::memcpy(&f, &out[0], 4);
    EXPECT_NEAR(f, k % 2 ? top : 0.0, 1e-7) << "level " << k;  // the UNorm scale's rounding at most
  }
}

TEST_F(SamplerFastPath, LevelOfDetailIsLog2OfTheScaleFactorRgba8Unorm) { compareLod(VK_FORMAT_R8G8B8A8_UNORM); }
TEST_F(SamplerFastPath, LevelOfDetailIsLog2OfTheScaleFactorSnorm) { compareLod(VK_FORMAT_R8G8B8A8_SNORM); }

TEST_F(SamplerFastPath, Rgba8UnormMatchesReferenceAndGenericPath) { compareAll(VK_FORMAT_R8G8B8A8_UNORM); }
TEST_F(SamplerFastPath, Bgra8UnormMatchesReferenceAndGenericPath) { compareAll(VK_FORMAT_B8G8R8A8_UNORM); }
TEST_F(SamplerFastPath, Bgra8SrgbMatchesReferenceAndGenericPath) { compareAll(VK_FORMAT_B8G8R8A8_SRGB); }

}  // namespace
}  // namespace vkrt
