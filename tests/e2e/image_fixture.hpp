// The image tests' fixture (image_test.cpp, blit_test.cpp): images with memory, whole-image layout transitions.
#pragma once

#include <vector>

#include "e2e/fixture.hpp"

namespace vkrt::test {

constexpr VkBufferUsageFlags kXfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
constexpr VkImageUsageFlags kImgXfer = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;

class ImageTest : public VulkanTest {
 protected:
  struct Img {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
  };

  static VkImageCreateInfo imageInfo(VkImageType type, VkFormat format, VkExtent3D extent, uint32_t mips,
                                     uint32_t layers, VkImageUsageFlags usage = kImgXfer) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = type;
    ci.format = format;
    ci.extent = extent;
    ci.mipLevels = mips;
    ci.arrayLayers = layers;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = usage;
    ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    return ci;
  }

  Img createImage(const VkImageCreateInfo& ci) {
    Img i;
    EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &i.image), VK_SUCCESS);
    if (!i.image) return i;  // no image: nothing to query or bind
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, i.image, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
    EXPECT_EQ(vkAllocateMemory(device, &mai, nullptr, &i.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device, i.image, i.memory, 0), VK_SUCCESS);
    return i;
  }
  void destroy(Img& i) {
    vkDestroyImage(device, i.image, nullptr);
    vkFreeMemory(device, i.memory, nullptr);
  }
  using VulkanTest::destroy;

  // A layout transition of the whole image, ordering transfers before and after it.
  static void transition(VkCommandBuffer cb, VkImage image, VkImageLayout from, VkImageLayout to) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = from == VK_IMAGE_LAYOUT_UNDEFINED ? 0 : VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                         1, &b);
  }
  static void toDst(VkCommandBuffer cb, VkImage image) {
    transition(cb, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  }
  static void dstToSrc(VkCommandBuffer cb, VkImage image) {
    transition(cb, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  }
  static uint8_t* bytes(const HostBuffer& b) { return static_cast<uint8_t*>(b.data); }
};

}  // namespace vkrt::test
