// vkrt image views for compiled shaders run below the Vulkan API (ComputeHarness::images): a device of the ICD's
// own entry points (createPlainDevice, which other tests below the API use too), 2D storage images bound to memory,
// their views, and their texels read and written in place.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::testing {

// An instance and a device of the ICD's own entry points (below the loader): one queue, nothing enabled.
inline void createPlainDevice(VkInstance* instance, VkDevice* device) {
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, instance), VK_SUCCESS);
  uint32_t n = 1;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  ASSERT_EQ(vkrt_EnumeratePhysicalDevices(*instance, &n, &pd), VK_SUCCESS);
  float prio = 1.0f;
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.queueCount = 1;
  q.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &q;
  ASSERT_EQ(vkrt_CreateDevice(pd, &dci, nullptr, device), VK_SUCCESS);
}

class RuntimeImages : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_NO_FATAL_FAILURE(createPlainDevice(&instance, &device)); }
  void TearDown() override {
    for (const Held& h : held) {
      vkrt_DestroyImageView(device, h.view, nullptr);
      vkrt_DestroyImage(device, h.image, nullptr);
      vkrt_FreeMemory(device, h.memory, nullptr);
    }
    vkrt_DestroyDevice(device, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }

  // A width x height 2D storage image of `format` with `layers` layers, and a view of all its layers (2D, or 2D
  // array where `layers` > 1).
  ImageView* makeImage(VkFormat format, uint32_t width, uint32_t height, uint32_t layers = 1) {
    Held h;
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {width, height, 1};
    ci.mipLevels = 1;
    ci.arrayLayers = layers;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.usage = VK_IMAGE_USAGE_STORAGE_BIT;
    EXPECT_EQ(vkrt_CreateImage(device, &ci, nullptr, &h.image), VK_SUCCESS);
    VkMemoryRequirements req;
    vkrt_GetImageMemoryRequirements(device, h.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    EXPECT_EQ(vkrt_AllocateMemory(device, &mai, nullptr, &h.memory), VK_SUCCESS);
    EXPECT_EQ(vkrt_BindImageMemory(device, h.image, h.memory, 0), VK_SUCCESS);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = h.image;
    vi.viewType = layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, layers};
    EXPECT_EQ(vkrt_CreateImageView(device, &vi, nullptr, &h.view), VK_SUCCESS);
    held.push_back(h);
    return fromHandle<ImageView>(h.view);
  }
  // The view's texels of `layer`, rows of `rowBytes` (tightly packed in `texels`), written or read in place.
  static void setTexels(const ImageView* v, uint32_t layer, const std::vector<uint8_t>& texels, size_t rowBytes) {
    for (uint32_t y = 0; y < v->image->mips[0].extent.height; ++y)
      std::memcpy(v->image->texel(0, layer, 0, y, 0), texels.data() + y * rowBytes, rowBytes);
  }
  static std::vector<uint8_t> texelsOf(const ImageView* v, uint32_t layer, size_t rowBytes) {
    const uint32_t h = v->image->mips[0].extent.height;
    std::vector<uint8_t> out(h * rowBytes);
    for (uint32_t y = 0; y < h; ++y)
      std::memcpy(out.data() + y * rowBytes, v->image->texel(0, layer, 0, y, 0), rowBytes);
    return out;
  }

  struct Held {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::vector<Held> held;
};

}  // namespace vkrt::testing
