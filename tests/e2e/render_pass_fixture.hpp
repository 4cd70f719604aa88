// The render pass tests' fixture (render_pass_*.cpp, formats_*.cpp): attachments (images of any format and sample
// count with a view), render passes of one or more subpasses, framebuffers, and read-back of an aspect of a layer.
// Images stay in VK_IMAGE_LAYOUT_GENERAL from creation on (one transition), so render passes, copies and clears all
// name GENERAL and the validation layer sees consistent layouts.
#pragma once

#include <cstring>
#include <deque>
#include <vector>

#include "e2e/image_fixture.hpp"

namespace vkrt::test {

class RenderPassTest : public ImageTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.features12.imagelessFramebuffer = VK_TRUE;
    o.features13.dynamicRendering = VK_TRUE;
    return o;
  }

  static VkImageAspectFlags aspectsOf(VkFormat f) {
    switch (f) {
      case VK_FORMAT_D16_UNORM:
      case VK_FORMAT_X8_D24_UNORM_PACK32:
      case VK_FORMAT_D32_SFLOAT: return VK_IMAGE_ASPECT_DEPTH_BIT;
      case VK_FORMAT_S8_UINT: return VK_IMAGE_ASPECT_STENCIL_BIT;
      case VK_FORMAT_D24_UNORM_S8_UINT:
      case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
      default: return VK_IMAGE_ASPECT_COLOR_BIT;
    }
  }

  struct Attachment {
    Img img;
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
    uint32_t width = 0, height = 0, layers = 1;
  };

  // A 2D image with `layers` layers and a view of all of them, transitioned to GENERAL.
  Attachment attachment(VkFormat format, uint32_t w, uint32_t h, uint32_t layers = 1,
                        VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT, VkImageUsageFlags extra = 0) {
    Attachment a;
    a.format = format;
    a.width = w;
    a.height = h;
    a.layers = layers;
    const VkImageAspectFlags aspects = aspectsOf(format);
    VkImageCreateInfo ci =
        imageInfo(VK_IMAGE_TYPE_2D, format, {w, h, 1}, 1, layers,
                  (aspects == VK_IMAGE_ASPECT_COLOR_BIT ? VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT
                                                        : VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) |
                      (samples == VK_SAMPLE_COUNT_1_BIT ? kImgXfer : 0) | extra);
    ci.samples = samples;
    a.img = createImage(ci);
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = a.img.image;
    vi.viewType = layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
    vi.format = format;
    vi.subresourceRange = {aspects, 0, 1, 0, layers};
    EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &a.view), VK_SUCCESS);
    VkCommandBuffer cb = beginOneTime();
    barrier(cb, a.img.image, aspects, VK_IMAGE_LAYOUT_UNDEFINED);
    submitAndWait(cb);
    return a;
  }

  void destroy(Attachment& a) {
    vkDestroyImageView(device, a.view, nullptr);
    ImageTest::destroy(a.img);
  }
  using ImageTest::destroy;

  // A full barrier on the image (old layout -> GENERAL).
  static void barrier(VkCommandBuffer cb, VkImage image, VkImageAspectFlags aspects,
                      VkImageLayout from = VK_IMAGE_LAYOUT_GENERAL) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspects, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
  }

  // One aspect of one layer, tightly packed (the spec's buffer packing for depth/stencil aspects).
  std::vector<uint8_t> readBack(const Attachment& a, VkImageAspectFlags aspect, uint32_t texelBytes,
                                uint32_t layer = 0) {
    HostBuffer b = createHostBuffer(VkDeviceSize(a.width) * a.height * texelBytes, kXfer);
    VkCommandBuffer cb = beginOneTime();
    barrier(cb, a.img.image, aspectsOf(a.format));
    VkBufferImageCopy r{};
    r.imageSubresource = {aspect, 0, layer, 1};
    r.imageExtent = {a.width, a.height, 1};
    vkCmdCopyImageToBuffer(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, b.buffer, 1, &r);
    submitAndWait(cb);
    std::vector<uint8_t> out(bytes(b), bytes(b) + b.size);
    destroy(b);
    return out;
  }

  uint32_t texelU32(const std::vector<uint8_t>& v, uint32_t i) {
    uint32_t x;
    std::memcpy(&x, v.data() + 4 * i, 4);
    return x;
  }

  void clearColor(const Attachment& a, VkClearColorValue c) {
    VkCommandBuffer cb = beginOneTime();
    VkImageSubresourceRange r{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, VK_REMAINING_ARRAY_LAYERS};
    vkCmdClearColorImage(cb, a.img.image, VK_IMAGE_LAYOUT_GENERAL, &c, 1, &r);
    barrier(cb, a.img.image, VK_IMAGE_ASPECT_COLOR_BIT);
    submitAndWait(cb);
  }

  static VkAttachmentDescription desc(VkFormat f, VkAttachmentLoadOp load,
                                      VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT,
                                      VkAttachmentLoadOp stencilLoad = VK_ATTACHMENT_LOAD_OP_DONT_CARE) {
    return {0,
            f,
            samples,
            load,
            VK_ATTACHMENT_STORE_OP_STORE,
            stencilLoad,
            VK_ATTACHMENT_STORE_OP_STORE,
            VK_IMAGE_LAYOUT_GENERAL,
            VK_IMAGE_LAYOUT_GENERAL};
  }

  VkRenderPass renderPass(const std::vector<VkAttachmentDescription>& atts,
                          const std::vector<VkSubpassDescription>& subs) {
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ci.attachmentCount = uint32_t(atts.size());
    ci.pAttachments = atts.data();
    ci.subpassCount = uint32_t(subs.size());
    ci.pSubpasses = subs.data();
    VkRenderPass rp = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_SUCCESS);
    return rp;
  }

  VkFramebuffer framebuffer(VkRenderPass rp, const std::vector<VkImageView>& views, uint32_t w, uint32_t h,
                            uint32_t layers = 1) {
    VkFramebufferCreateInfo ci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    ci.renderPass = rp;
    ci.attachmentCount = uint32_t(views.size());
    ci.pAttachments = views.data();
    ci.width = w;
    ci.height = h;
    ci.layers = layers;
    VkFramebuffer fb = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_SUCCESS);
    return fb;
  }

  // The clear values are kept by the fixture until the test ends (the begin info points at them).
  VkRenderPassBeginInfo beginInfo(VkRenderPass rp, VkFramebuffer fb, VkRect2D area, std::vector<VkClearValue> values) {
    clearValues_.push_back(std::move(values));
    const std::vector<VkClearValue>& clears = clearValues_.back();
    VkRenderPassBeginInfo bi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    bi.renderPass = rp;
    bi.framebuffer = fb;
    bi.renderArea = area;
    bi.clearValueCount = uint32_t(clears.size());
    bi.pClearValues = clears.data();
    return bi;
  }

  std::deque<std::vector<VkClearValue>> clearValues_;

  static bool inside(const VkRect2D& r, uint32_t x, uint32_t y) {
    return int64_t(x) >= r.offset.x && int64_t(x) < r.offset.x + int64_t(r.extent.width) && int64_t(y) >= r.offset.y &&
           int64_t(y) < r.offset.y + int64_t(r.extent.height);
  }
};

// The same without the validation layer, for misuse reported by vkrt.
class RenderPassMisuseTest : public RenderPassTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = RenderPassTest::options();
    o.validation = false;
    return o;
  }
};

}  // namespace vkrt::test
