// Render pass misuse reported by vkrt (the validation layer off): creation rules of render passes and
// framebuffers, begin-time rules, the recording rules of commands inside and outside a render pass instance.
// Each rule's valid side is exercised by the valid tests (render_pass_test.cpp and the others), which run with the
// layer on and fail on any vkrt report.
#include "e2e/render_pass_fixture.hpp"

namespace vkrt::test {
namespace {

class PassMisuseTest : public RenderPassMisuseTest {
 protected:
  void SetUp() override {
    RenderPassMisuseTest::SetUp();
    if (!onVkrt()) GTEST_SKIP() << "vkrt's own reports";
  }

  VkResult tryPass(const std::vector<VkAttachmentDescription>& atts, const VkSubpassDescription& sub) {
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ci.attachmentCount = uint32_t(atts.size());
    ci.pAttachments = atts.data();
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    VkRenderPass rp = VK_NULL_HANDLE;
    VkResult r = vkCreateRenderPass(device, &ci, nullptr, &rp);
    vkDestroyRenderPass(device, rp, nullptr);
    return r;
  }
};

TEST_F(PassMisuseTest, RenderPassCreation) {
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL}, r1{1, VK_IMAGE_LAYOUT_GENERAL}, r5{5, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r5;
  const auto color = desc(VK_FORMAT_R8G8B8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD);
  EXPECT_EQ(tryPass({color}, sub), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRenderPassCreateInfo-attachment-00834");
  sub.pColorAttachments = &r0;
  EXPECT_EQ(tryPass({desc(VK_FORMAT_D16_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD)}, sub), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pColorAttachments-02648");
  // Two color attachments of 1 and 4 samples.
  VkAttachmentReference two[2] = {r0, r1};
  sub.colorAttachmentCount = 2;
  sub.pColorAttachments = two;
  EXPECT_EQ(tryPass({color, desc(VK_FORMAT_R8G8B8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD, VK_SAMPLE_COUNT_4_BIT)}, sub),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pColorAttachments-06868");
  // Resolving a single-sampled attachment, and into a multisampled one.
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r0;
  sub.pResolveAttachments = &r1;
  EXPECT_EQ(tryPass({color, color}, sub), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pResolveAttachments-00848");
  const auto ms = desc(VK_FORMAT_R8G8B8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD, VK_SAMPLE_COUNT_4_BIT);
  EXPECT_EQ(tryPass({ms, ms}, sub), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pResolveAttachments-00849");
  EXPECT_EQ(tryPass({ms, desc(VK_FORMAT_B8G8R8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD)}, sub),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pResolveAttachments-00850");
  // The valid sides.
  EXPECT_EQ(tryPass({ms, color}, sub), VK_SUCCESS);
  sub.pResolveAttachments = nullptr;
  sub.pDepthStencilAttachment = &r1;
  EXPECT_EQ(tryPass({color, desc(VK_FORMAT_R8G8B8A8_UNORM, VK_ATTACHMENT_LOAD_OP_LOAD)}, sub),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pDepthStencilAttachment-02650");
  EXPECT_EQ(tryPass({color, desc(VK_FORMAT_D32_SFLOAT, VK_ATTACHMENT_LOAD_OP_LOAD, VK_SAMPLE_COUNT_4_BIT)}, sub),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription-pDepthStencilAttachment-01418");
  EXPECT_EQ(tryPass({color, desc(VK_FORMAT_D32_SFLOAT, VK_ATTACHMENT_LOAD_OP_LOAD)}, sub), VK_SUCCESS);
}

TEST_F(PassMisuseTest, FramebufferAndBeginRules) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4);
  Attachment small = attachment(VK_FORMAT_R8G8B8A8_UNORM, 2, 2);
  Attachment d = attachment(VK_FORMAT_D16_UNORM, 4, 4);
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r0;
  VkRenderPass rp = renderPass({desc(a.format, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  VkFramebufferCreateInfo ci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO, nullptr, 0, rp, 1, &small.view, 4, 4, 1};
  VkFramebuffer fb = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkFramebufferCreateInfo-flags-04533");
  ci.pAttachments = &d.view;
  EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkFramebufferCreateInfo-pAttachments-00880");
  ci.attachmentCount = 0;
  EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkFramebufferCreateInfo-attachmentCount-00876");
  ci.attachmentCount = 1;
  ci.pAttachments = &a.view;
  ASSERT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_SUCCESS);

  VkClearValue cv{};
  VkCommandBuffer cb = beginOneTime();
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {4, 4}}, {});
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-VkRenderPassBeginInfo-clearValueCount-00902");
  bi = beginInfo(rp, fb, {{1, 0}, {4, 4}}, {cv});
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-VkRenderPassBeginInfo-pNext-02852");
  // A render pass of another format is not compatible with the framebuffer.
  VkRenderPass other = renderPass({desc(VK_FORMAT_B8G8R8A8_UNORM, VK_ATTACHMENT_LOAD_OP_CLEAR)}, {sub});
  bi = beginInfo(other, fb, {{0, 0}, {4, 4}}, {cv});
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-VkRenderPassBeginInfo-renderPass-00904");
  // Outside a render pass instance.
  vkCmdEndRenderPass(cb);
  expectVkrtMessage("VUID-vkCmdEndRenderPass-renderpass");
  vkCmdNextSubpass(cb, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-vkCmdNextSubpass-renderpass");
  VkClearAttachment clear{VK_IMAGE_ASPECT_COLOR_BIT, 0, {}};
  VkClearRect rect{{{0, 0}, {2, 2}}, 0, 1};
  vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
  expectVkrtMessage("VUID-vkCmdClearAttachments-renderpass");
  vkCmdEndRendering(cb);
  expectVkrtMessage("VUID-vkCmdEndRendering-renderpass");
  // Inside one.
  bi = beginInfo(rp, fb, {{0, 0}, {2, 2}}, {cv});
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  EXPECT_TRUE(vkrtMessages().empty());
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-vkCmdBeginRenderPass-renderpass");
  vkCmdNextSubpass(cb, VK_SUBPASS_CONTENTS_INLINE);
  expectVkrtMessage("VUID-vkCmdNextSubpass-None-00909");
  vkCmdEndRendering(cb);
  expectVkrtMessage("VUID-vkCmdEndRendering-None-06161");
  clear.colorAttachment = 1;
  vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
  expectVkrtMessage("VUID-vkCmdClearAttachments-aspectMask-07271");
  clear.colorAttachment = 0;
  rect.rect.extent = {3, 2};
  vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
  expectVkrtMessage("VUID-vkCmdClearAttachments-pRects-00016");
  rect.rect.extent = {2, 2};
  rect.layerCount = 0;
  vkCmdClearAttachments(cb, 1, &clear, 1, &rect);
  expectVkrtMessage("VUID-vkCmdClearAttachments-layerCount-01934");
  HostBuffer buf = createHostBuffer(64, kXfer);
  VkBufferCopy bc{0, 32, 16};
  vkCmdCopyBuffer(cb, buf.buffer, buf.buffer, 1, &bc);
  expectVkrtMessage("VUID-vkCmdCopyBuffer-renderpass");
  vkCmdDispatch(cb, 1, 1, 1);
  expectVkrtMessage("VUID-vkCmdDispatch-renderpass");
  VkClearColorValue c{};
  VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cb, small.img.image, VK_IMAGE_LAYOUT_GENERAL, &c, 1, &range);
  expectVkrtMessage("VUID-vkCmdClearColorImage-renderpass");
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkEndCommandBuffer-commandBuffer-00060");
  vkCmdEndRenderPass(cb);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  destroy(buf);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  vkDestroyRenderPass(device, other, nullptr);
  destroy(a);
  destroy(small);
  destroy(d);
}

TEST_F(PassMisuseTest, EndRenderPassBeforeTheLastSubpass) {
  Attachment a = attachment(VK_FORMAT_R8G8B8A8_UNORM, 2, 2);
  VkAttachmentReference r0{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &r0;
  VkRenderPass rp = renderPass({desc(a.format, VK_ATTACHMENT_LOAD_OP_LOAD)}, {sub, sub});
  VkFramebuffer fb = framebuffer(rp, {a.view}, 2, 2);
  VkCommandBuffer cb = beginOneTime();
  VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {2, 2}}, {});
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdEndRenderPass(cb);
  expectVkrtMessage("VUID-vkCmdEndRenderPass-None-00910");
  vkCmdNextSubpass(cb, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdEndRenderPass(cb);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
}

TEST_F(PassMisuseTest, ImageAndResolveRules) {
  // A multisampled image that is mip-mapped, and vkCmdResolveImage into a multisampled destination.
  VkImageCreateInfo ci =
      imageInfo(VK_IMAGE_TYPE_2D, VK_FORMAT_R8G8B8A8_UNORM, {4, 4, 1}, 2, 1, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  ci.samples = VK_SAMPLE_COUNT_4_BIT;
  VkImage img = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &img), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkImageCreateInfo-samples-02257");
  ci.mipLevels = 1;
  ci.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
  EXPECT_EQ(vkCreateImage(device, &ci, nullptr, &img), VK_ERROR_FORMAT_NOT_SUPPORTED);
  expectVkrtMessage("VUID-VkImageCreateInfo-samples-02258");
  Attachment ms = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4, 1, VK_SAMPLE_COUNT_4_BIT, kImgXfer);
  Attachment ms2 = attachment(VK_FORMAT_R8G8B8A8_UNORM, 4, 4, 1, VK_SAMPLE_COUNT_4_BIT, kImgXfer);
  Attachment one = attachment(VK_FORMAT_B8G8R8A8_UNORM, 4, 4);
  VkImageResolve r{{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {4, 4, 1}};
  VkCommandBuffer cb = beginOneTime();
  vkCmdResolveImage(cb, ms.img.image, VK_IMAGE_LAYOUT_GENERAL, ms2.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
  expectVkrtMessage("VUID-vkCmdResolveImage-dstImage-00259");
  vkCmdResolveImage(cb, ms.img.image, VK_IMAGE_LAYOUT_GENERAL, one.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &r);
  expectVkrtMessage("VUID-vkCmdResolveImage-srcImage-01386");
  // A multisampled image is not copied to a buffer.
  HostBuffer buf = createHostBuffer(1024, kXfer);
  VkBufferImageCopy bc{0, 0, 0, {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, {}, {4, 4, 1}};
  vkCmdCopyImageToBuffer(cb, ms.img.image, VK_IMAGE_LAYOUT_GENERAL, buf.buffer, 1, &bc);
  expectVkrtMessage("VUID-vkCmdCopyImageToBuffer-srcImage-07973");
  // A depth image is no clear-color target and a color image no clear-depth one.
  Attachment d = attachment(VK_FORMAT_D32_SFLOAT, 4, 4);
  VkClearColorValue c{};
  VkImageSubresourceRange cr{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cb, d.img.image, VK_IMAGE_LAYOUT_GENERAL, &c, 1, &cr);
  expectVkrtMessage("VUID-vkCmdClearColorImage-image-00007");
  VkClearDepthStencilValue dv{0.5f, 0};
  VkImageSubresourceRange dr{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  vkCmdClearDepthStencilImage(cb, one.img.image, VK_IMAGE_LAYOUT_GENERAL, &dv, 1, &dr);
  expectVkrtMessage("VUID-vkCmdClearDepthStencilImage-image-00014");
  dr.aspectMask = VK_IMAGE_ASPECT_STENCIL_BIT;
  vkCmdClearDepthStencilImage(cb, d.img.image, VK_IMAGE_LAYOUT_GENERAL, &dv, 1, &dr);
  expectVkrtMessage("VUID-vkCmdClearDepthStencilImage-image-02825");
  // Copying both aspects of a combined format to a buffer in one region.
  Attachment ds = attachment(VK_FORMAT_D24_UNORM_S8_UINT, 4, 4);
  bc.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
  vkCmdCopyImageToBuffer(cb, ds.img.image, VK_IMAGE_LAYOUT_GENERAL, buf.buffer, 1, &bc);
  expectVkrtMessage("VUID-VkBufferImageCopy-aspectMask-00212");
  submitAndWait(cb);
  destroy(buf);
  destroy(ms);
  destroy(ms2);
  destroy(one);
  destroy(d);
  destroy(ds);
}

}  // namespace
}  // namespace vkrt::test

namespace vkrt::test {
namespace {

TEST_F(PassMisuseTest, BlitsOfDepthAndSecondariesAndDynamicRendering) {
  // A depth format has no BLIT_DST (only D16 and D32 have BLIT_SRC, as required).
  Attachment d = attachment(VK_FORMAT_D32_SFLOAT, 4, 4);
  Attachment d2 = attachment(VK_FORMAT_D32_SFLOAT, 4, 4);
  VkImageBlit b{{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                {{0, 0, 0}, {4, 4, 1}},
                {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1},
                {{0, 0, 0}, {4, 4, 1}}};
  VkCommandBuffer cb = beginOneTime();
  vkCmdBlitImage(cb, d.img.image, VK_IMAGE_LAYOUT_GENERAL, d2.img.image, VK_IMAGE_LAYOUT_GENERAL, 1, &b,
                 VK_FILTER_NEAREST);
  expectVkrtMessage("VUID-vkCmdBlitImage-dstImage-02000");
  // A secondary that continues a render pass needs a live render pass (or inherited rendering formats), and is
  // executed inside a render pass instance only.
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, commandPool,
                                  VK_COMMAND_BUFFER_LEVEL_SECONDARY, 1};
  VkCommandBuffer sec = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &sec), VK_SUCCESS);
  VkCommandBufferInheritanceInfo inh{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
  VkCommandBufferBeginInfo sbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO, nullptr,
                               VK_COMMAND_BUFFER_USAGE_RENDER_PASS_CONTINUE_BIT, &inh};
  EXPECT_EQ(vkBeginCommandBuffer(sec, &sbi), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkCommandBufferBeginInfo-flags-06002");
  const VkFormat color = VK_FORMAT_R8G8B8A8_UNORM;
  VkCommandBufferInheritanceRenderingInfo ir{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_RENDERING_INFO};
  ir.colorAttachmentCount = 1;
  ir.pColorAttachmentFormats = &color;
  ir.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  inh.pNext = &ir;
  ASSERT_EQ(vkBeginCommandBuffer(sec, &sbi), VK_SUCCESS);
  vkCmdEndRendering(sec);
  expectVkrtMessage("VUID-vkCmdEndRendering-commandBuffer-06162");
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  vkCmdExecuteCommands(cb, 1, &sec);
  expectVkrtMessage("VUID-vkCmdExecuteCommands-pCommandBuffers-00100");
  // vkCmdBeginRendering: a resolve of a single-sampled attachment, a render area outside the view.
  Attachment a = attachment(color, 4, 4);
  Attachment r = attachment(color, 4, 4);
  VkRenderingAttachmentInfo ca{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  ca.imageView = a.view;
  ca.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  ca.resolveMode = VK_RESOLVE_MODE_AVERAGE_BIT;
  ca.resolveImageView = r.view;
  ca.resolveImageLayout = VK_IMAGE_LAYOUT_GENERAL;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {4, 4}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &ca;
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-VkRenderingAttachmentInfo-imageView-06132");
  ca.resolveMode = VK_RESOLVE_MODE_NONE;
  ri.renderArea = {{2, 0}, {4, 4}};
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-VkRenderingInfo-imageView-06075");
  ri.renderArea = {{0, 0}, {4, 4}};
  ri.layerCount = 0;
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-VkRenderingInfo-viewMask-06069");
  ri.layerCount = 1;
  vkCmdBeginRendering(cb, &ri);
  vkCmdEndRenderPass(cb);
  expectVkrtMessage("VUID-vkCmdEndRenderPass-None-06170");
  vkCmdEndRendering(cb);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  vkFreeCommandBuffers(device, commandPool, 1, &sec);
  destroy(d);
  destroy(d2);
  destroy(a);
  destroy(r);
}

}  // namespace
}  // namespace vkrt::test
