// Render passes through the loader and the validation layer: load-op clears inside the render area only (color,
// depth, stencil), LOAD keeping contents, two subpasses with the second attachment cleared at its first use,
// vkCmdClearAttachments rects and layers, imageless framebuffers, secondary command buffers continuing a render
// pass, and the queue family's graphics bit. Expected bytes are computed here from the spec's encodings.
#include <cmath>
#include <cstring>

#include "e2e/render_pass_fixture.hpp"

namespace vkrt::test {
namespace {

constexpr uint32_t kRed = 0xFF0000FFu;    // R8G8B8A8_UNORM (1, 0, 0, 1) as a little-endian word
constexpr uint32_t kGreen = 0xFF00FF00u;  // (0, 1, 0, 1)
constexpr uint32_t kBlue = 0xFFFF0000u;   // (0, 0, 1, 1)
constexpr VkClearColorValue kRedF{{1, 0, 0, 1}}, kGreenF{{0, 1, 0, 1}}, kBlueF{{0, 0, 1, 1}};

VkClearValue colorValue(VkClearColorValue c) {
  VkClearValue v;
  v.color = c;
  return v;
}

TEST_F(RenderPassTest, QueueFamilyHasGraphics) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, nullptr);
  std::vector<VkQueueFamilyProperties> f(n);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &n, f.data());
  EXPECT_TRUE(f[0].queueFlags & VK_QUEUE_GRAPHICS_BIT);
  VkExtent2D g{};
  VkRenderPass rp = renderPass({desc(VK_FORMAT_R8G8B8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD)}, {VkSubpassDescription{}});
  vkGetRenderAreaGranularity(device, rp, &g);
  if (onVkrt()) {
    EXPECT_TRUE(g.width == 1 && g.height == 1);
  }
  vkDestroyRenderPass(device, rp, nullptr);
}

TEST_F(RenderPassTest, ClearLoadOpWritesTheRenderAreaOnlyAndLoadKeepsContents) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 8, 8);
  Attachment b = attachment(VK_FORMAT_R8G8B8A8_UNORM, 8, 8);
  clearColor(a, kBlueF);
  clearColor(b, kGreenF);
  VkAttachmentReference refs[2] = {{0, VK_IMAGE_LAYOUT_GENERAL}, {1, VK_IMAGE_LAYOUT_GENERAL}};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 2;
  sub.pColorAttachments = refs;
  VkRenderPass rp =
      renderPass({desc(a.format, VK_ATTACHMENT_LOAD_OP_CLEAR), desc(b.format, VK_ATTACHMENT_LOAD_OP_LOAD)}, {sub});
  VkFramebuffer fb = framebuffer(rp, {a.view, b.view}, 8, 8);
  const VkRect2D area{{2, 1}, {4, 3}};
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, area, {colorValue(kRedF), colorValue(kBlueF)});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  std::vector<uint8_t> pa = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4), pb = readBack(b, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      EXPECT_EQ(texelU32(pa, y * 8 + x), inside(area, x, y) ? kRed : kBlue) << x << "," << y;
      EXPECT_EQ(texelU32(pb, y * 8 + x), kGreen) << x << "," << y;
    }
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
  destroy(b);
}

// Depth and stencil load-op clears of the combined formats, after vkCmdClearDepthStencilImage filled the image:
// D24 depth reads back as 32 bits with the value in bits 0..23 ("Depth/Stencil Formats" copy packing), D32 as a
// float, stencil as bytes.
TEST_F(RenderPassTest, DepthAndStencilClearsOfCombinedFormats) {
  for (VkFormat f : {VK_FORMAT_D24_UNORM_S8_UINT, VK_FORMAT_D32_SFLOAT_S8_UINT}) {
    SCOPED_TRACE(f);
    Attachment d = attachment(f, 6, 5);
    VkCommandBuffer cb = beginOneTime();
    VkClearDepthStencilValue init{1.0f, 3};
    VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, 0, 1, 0, 1};
    vkCmdClearDepthStencilImage(cb, d.img.image, VK_IMAGE_LAYOUT_GENERAL, &init, 1, &range);
    barrier(cb, d.img.image, range.aspectMask);
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_GENERAL};
    VkSubpassDescription sub{};
    sub.pDepthStencilAttachment = &ref;
    VkRenderPass rp =
        renderPass({desc(f, VK_ATTACHMENT_LOAD_OP_CLEAR, VK_SAMPLE_COUNT_1_BIT, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
    VkFramebuffer fb = framebuffer(rp, {d.view}, 6, 5);
    VkClearValue v;
    v.depthStencil = {0.25f, 0x5A};
    const VkRect2D area{{1, 2}, {4, 2}};
    VkRenderPassBeginInfo bi = beginInfo(rp, fb, area, {v});
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdEndRenderPass(cb);
    submitAndWait(cb);
    std::vector<uint8_t> depth = readBack(d, VK_IMAGE_ASPECT_DEPTH_BIT, 4),
                         stencil = readBack(d, VK_IMAGE_ASPECT_STENCIL_BIT, 1);
    const bool d24 = f == VK_FORMAT_D24_UNORM_S8_UINT;
    for (uint32_t y = 0; y < 5; ++y)
      for (uint32_t x = 0; x < 6; ++x) {
        const bool in = inside(area, x, y);
        const uint32_t word = texelU32(depth, y * 6 + x);
        if (d24) {
          // 0.25 * (2^24 - 1) = 4194303.75 -> 4194304; 1.0 -> 0xFFFFFF. Bits 24..31 are undefined.
          EXPECT_EQ(word & 0xFFFFFFu, in ? 4194304u : 0xFFFFFFu) << x << "," << y;
        } else {
          float z;
          std::memcpy(&z, &word, 4);
          EXPECT_EQ(z, in ? 0.25f : 1.0f) << x << "," << y;
        }
        EXPECT_EQ(stencil[y * 6 + x], in ? 0x5A : 3) << x << "," << y;
      }
    vkDestroyFramebuffer(device, fb, nullptr);
    vkDestroyRenderPass(device, rp, nullptr);
    destroy(d);
  }
}

// Two subpasses, each with its own color attachment: the second is cleared at its first use (subpass 1), and
// vkCmdClearAttachments in subpass 1 addresses the subpass's color attachment 0 (attachment 1 of the pass).
TEST_F(RenderPassTest, NextSubpassWithTwoColorAttachments) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4);
  Attachment b = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4);
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL}, r1{1, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription subs[2] = {};
  subs[0].colorAttachmentCount = 1;
  subs[0].pColorAttachments = &r0;
  subs[1].colorAttachmentCount = 1;
  subs[1].pColorAttachments = &r1;
  VkSubpassDependency dep{0,
                          1,
                          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                          VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                          VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                          0};
  std::vector<VkAttachmentDescription> atts = {desc(a.format, VK_ATTACHMENT_LOAD_OP_CLEAR),
                                               desc(b.format, VK_ATTACHMENT_LOAD_OP_CLEAR)};
  VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  ci.attachmentCount = 2;
  ci.pAttachments = atts.data();
  ci.subpassCount = 2;
  ci.pSubpasses = subs;
  ci.dependencyCount = 1;
  ci.pDependencies = &dep;
  VkRenderPass rp = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_SUCCESS);
  VkFramebuffer fb = framebuffer(rp, {a.view, b.view}, 4, 4);
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {4, 4}}, {colorValue(kRedF), colorValue(kGreenF)});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdNextSubpass(cb, VK_SUBPASS_CONTENTS_INLINE);
  VkClearAttachment clear{VK_IMAGE_ASPECT_COLOR_BIT, 0, colorValue(kBlueF)};
  VkClearRect rect{{{1, 1}, {2, 2}}, 0, 1};
  vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  std::vector<uint8_t> pa = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4), pb = readBack(b, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) {
      EXPECT_EQ(texelU32(pa, y * 4 + x), kRed);
      EXPECT_EQ(texelU32(pb, y * 4 + x), inside(rect.rect, x, y) ? kBlue : kGreen) << x << "," << y;
    }
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
  destroy(b);
}

// vkCmdClearAttachments on a layered framebuffer: a color rect in layer 1 only, a depth rect in layers 0..1; the
// view covers layers 0..1 of a 3-layer image, so layer 2 stays as it was.
TEST_F(RenderPassTest, ClearAttachmentsRectsAndLayers) {
  Attachment c = attachment(VK_FORMAT_R8G8B8A8_UNORM, 5, 4, 2);
  Attachment d = attachment(VK_FORMAT_D32_SFLOAT, 5, 4, 2);
  clearColor(c, kGreenF);
  VkAttachmentReference cr{0, VK_IMAGE_LAYOUT_GENERAL}, dr{1, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &cr;
  sub.pDepthStencilAttachment = &dr;
  VkRenderPass rp =
      renderPass({desc(c.format, VK_ATTACHMENT_LOAD_OP_LOAD), desc(d.format, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  VkFramebuffer fb = framebuffer(rp, {c.view, d.view}, 5, 4, 2);
  VkClearValue dv;
  dv.depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {5, 4}}, {colorValue(kRedF), dv});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  VkClearAttachment clears[2] = {{VK_IMAGE_ASPECT_COLOR_BIT, 0, colorValue(kBlueF)},
                                 {VK_IMAGE_ASPECT_DEPTH_BIT, 0, {}}};
  clears[1].clearValue.depthStencil = {0.5f, 0};
  VkClearRect colorRect{{{1, 0}, {3, 2}}, 1, 1}, depthRect{{{0, 2}, {2, 2}}, 0, 2};
  vkCmdClearAttachments(cb, 1, &clears[0], 1, &colorRect);
  vkCmdClearAttachments(cb, 1, &clears[1], 1, &depthRect);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  for (uint32_t l = 0; l < 2; ++l) {
    std::vector<uint8_t> pc = readBack(c, VK_IMAGE_ASPECT_COLOR_BIT, 4, l),
                         pd = readBack(d, VK_IMAGE_ASPECT_DEPTH_BIT, 4, l);
    for (uint32_t y = 0; y < 4; ++y)
      for (uint32_t x = 0; x < 5; ++x) {
        EXPECT_EQ(texelU32(pc, y * 5 + x), l == 1 && inside(colorRect.rect, x, y) ? kBlue : kGreen)
            << l << ":" << x << "," << y;
        float z;
        std::memcpy(&z, pd.data() + 4 * (y * 5 + x), 4);
        EXPECT_EQ(z, inside(depthRect.rect, x, y) ? 0.5f : 1.0f) << l << ":" << x << "," << y;
      }
  }
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(c);
  destroy(d);
}

// An imageless framebuffer: the view is given at vkCmdBeginRenderPass (VkRenderPassAttachmentBeginInfo).
TEST_F(RenderPassTest, ImagelessFramebuffer) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 3);
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r0;
  VkRenderPass rp = renderPass({desc(a.format, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  VkFramebufferAttachmentImageInfo ii{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENT_IMAGE_INFO};
  ii.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | kImgXfer;
  ii.width = 4;
  ii.height = 3;
  ii.layerCount = 1;
  ii.viewFormatCount = 1;
  ii.pViewFormats = &a.format;
  VkFramebufferAttachmentsCreateInfo ai{VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO};
  ai.attachmentImageInfoCount = 1;
  ai.pAttachmentImageInfos = &ii;
  VkFramebufferCreateInfo ci{
      VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO, &ai, VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT, rp, 1, nullptr, 4, 3, 1};
  VkFramebuffer fb = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_SUCCESS);
  VkRenderPassAttachmentBeginInfo ab{VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO, nullptr, 1, &a.view};
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {4, 3}}, {colorValue(kRedF)});
  bi.pNext = &ab;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t i = 0; i < 12; ++i) EXPECT_EQ(texelU32(p, i), kRed);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
}

// A secondary command buffer that continues the render pass (RENDER_PASS_CONTINUE, VkCommandBufferInheitanceInfo):
// its vkCmdClearAttachments renders into the primary's render pass instance.
TEST_F(RenderPassTest, SecondaryCommandBufferContinuesTheRenderPass) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4);
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r0;
  VkRenderPass rp = renderPass({desc(a.format, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  VkFramebuffer fb = framebuffer(rp, {a.view}, 4, 4);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, commandPool,
                                  VK_COMMAND_BUFFER_LEVEL_SECONDARY, 1};
  VkCommandBuffer sec = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &sec), VK_SUCCESS);
  VkCommandBufferInheritanceInfo inh{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO, nullptr, rp, 0, fb};
  VkCommandBufferBeginInfo sbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr,
                               VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT, &inh};
  ASSERT_EQ(vkBeginCommandBuffer(sec, &sbi), VK_SUCCESS);
  VkClearAttachment clear{VK_IMAGE_ASPECT_COLOR_BIT, 0, colorValue(kBlueF)};
  VkClearRect rect{{{0, 2}, {4, 2}}, 0, 1};
  vkCmdClearAttachments(sec, 1, &clear, 1, &rect);
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {4, 4}}, {colorValue(kRedF)});
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_SECONDARY_COMMAND_BUFFERS);
  vkCmdExecuteCommands(cb, 1, &sec);
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  std::vector<uint8_t> p = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4);
  for (uint32_t y = 0; y < 4; ++y)
    for (uint32_t x = 0; x < 4; ++x) EXPECT_EQ(texelU32(p, y * 4 + x), y >= 2 ? kBlue : kRed) << x << "," << y;
  vkFreeCommandBuffers(device, commandPool, 1, &sec);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
}

}  // namespace
}  // namespace vkrt::test
