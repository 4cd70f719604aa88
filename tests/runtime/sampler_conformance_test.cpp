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

}  // namespace
}  // namespace vkrt
