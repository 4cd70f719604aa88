// Multiview (Vulkan 1.1): a render pass with VkRenderPassMultiviewCreateInfo and vkCmdBeginRendering's viewMask
// draw once per view into the layer of the view's index, with gl_ViewIndex in the vertex and the fragment shader;
// the view-mask rules vkrt checks, both sides.
#include "e2e/subpass_fixture.hpp"
#include "multiview.frag.spv.h"
#include "multiview.vert.spv.h"

namespace vkrt::test {
namespace {

class MultiviewTest : public SubpassTest {
 protected:
  // What the shaders draw in view v (computed here from their text, not by vkrt): view v covers the pixel columns
  // [16 v, 16 v + 16) with red 1 for view 0, green 1 for view 1, blue 0.25 + 0.5 v.
  static uint32_t expected(uint32_t view, uint32_t x, uint32_t background) {
    const bool inside = x >= 16 * view && x < 16 * view + 16;
    return inside ? rgba8(view == 0, view == 1, 0.25 + 0.5 * view, 1) : background;
  }

  // Checks layer `layer` of `a` against view `layer`'s drawing (or `background` everywhere when not `drawn`).
  void checkLayer(const Attachment& a, uint32_t layer, bool drawn, uint32_t background) {
    std::vector<uint8_t> px = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4, layer);
    int bad = 0;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const uint32_t want = drawn ? expected(layer, x, background) : background;
        const uint32_t got = texelU32(px, y * kW + x);
        if (!near(got, want) && bad++ < 4)
          ADD_FAILURE() << "layer " << layer << " pixel (" << x << ", " << y << "): 0x" << std::hex << got
                        << ", expected 0x" << want;
      }
    EXPECT_EQ(bad, 0) << "layer " << layer;
  }

  // A render pass (vkCreateRenderPass with VkRenderPassMultiviewCreateInfo) of one subpass with view mask `mask`,
  // clearing its color attachment to transparent black.
  VkRenderPass multiviewPass(uint32_t mask) {
    VkAttachmentDescription att = desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR);
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_GENERAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &ref;
    VkRenderPassMultiviewCreateInfo mv{VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO};
    mv.subpassCount = 1;
    mv.pViewMasks = &mask;
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, &mv};
    ci.attachmentCount = 1;
    ci.pAttachments = &att;
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    VkRenderPass rp = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_SUCCESS);
    return rp;
  }

  // Draws the two-view rectangle in a render pass with view mask `mask` on a two-layer attachment first filled with
  // `fill`, and checks both layers: views in the mask cleared and drawn, the others untouched.
  void renderPassViews(uint32_t mask) {
    Attachment a = attachment(kFormat, kW, kH, 2);
    const uint32_t fill = rgba8(0, 0, 1, 1);
    clearColor(a, {{0, 0, 1, 1}});
    VkRenderPass rp = multiviewPass(mask);
    VkFramebuffer fb = framebuffer(rp, {a.view}, kW, kH, 1);
    PipelineDesc d;
    d.vs = kSpv_multiview_vert;
    d.vsBytes = sizeof kSpv_multiview_vert;
    d.fs = kSpv_multiview_frag;
    d.fsBytes = sizeof kSpv_multiview_frag;
    d.renderPass = rp;
    VkPipeline p;
    ASSERT_EQ(pipeline(d, &p), VK_SUCCESS);
    VkClearValue clear{};
    VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {kW, kH}}, {clear});
    VkCommandBuffer cb = beginOneTime();
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdDraw(cb, 6, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    submitAndWait(cb);
    for (uint32_t l = 0; l < 2; ++l) {
      const bool inMask = (mask >> l) & 1;
      checkLayer(a, l, inMask, inMask ? 0u : fill);
    }
    vkDestroyFramebuffer(device, fb, nullptr);
    vkDestroyRenderPass(device, rp, nullptr);
    destroy(a);
  }
};

TEST_F(MultiviewTest, FeatureAndLimitsAdvertised) {
  VkPhysicalDeviceMultiviewFeatures f{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_EQ(f.multiview, VK_TRUE);
  EXPECT_EQ(f.multiviewGeometryShader, VK_FALSE);
  EXPECT_EQ(f.multiviewTessellationShader, VK_FALSE);
  VkPhysicalDeviceMultiviewProperties p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_PROPERTIES};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  EXPECT_GE(p.maxMultiviewViewCount, 6u);                  // the spec's required limit
  EXPECT_GE(p.maxMultiviewInstanceIndex, (1u << 27) - 1);  // likewise
}

TEST_F(MultiviewTest, RenderPassTwoViews) { renderPassViews(0b11); }

// Only view 1: layer 0 keeps what it held (neither cleared nor drawn).
TEST_F(MultiviewTest, RenderPassSecondViewOnly) { renderPassViews(0b10); }

TEST_F(MultiviewTest, DynamicRenderingTwoViews) {
  Attachment a = attachment(kFormat, kW, kH, 2);
  clearColor(a, {{0, 0, 1, 1}});
  PipelineDesc d;
  d.vs = kSpv_multiview_vert;
  d.vsBytes = sizeof kSpv_multiview_vert;
  d.fs = kSpv_multiview_frag;
  d.fsBytes = sizeof kSpv_multiview_frag;
  d.viewMask = 0b11;
  VkPipeline p;
  ASSERT_EQ(pipeline(d, &p), VK_SUCCESS);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = a.view;
  color.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {kW, kH}};
  ri.layerCount = 1;
  ri.viewMask = 0b11;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &color;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
  vkCmdDraw(cb, 6, 1, 0, 0);
  vkCmdEndRendering(cb);
  submitAndWait(cb);
  checkLayer(a, 0, true, 0);
  checkLayer(a, 1, true, 0);
  destroy(a);
}

// ---- the rules, with multiview enabled (vkrt's own reports) ----

class MultiviewMisuseTest : public MultiviewTest {
 protected:
  bool validation() const override { return false; }
};

// VUID-VkRenderPassMultiviewCreateInfo-pViewMasks-06697 and VkSubpassDescription2-viewMask-06706: view indices
// below maxMultiviewViewCount (6); six views (0x3F) are fine.
TEST_F(MultiviewMisuseTest, ViewMaskPastMaxViewCount) {
  VkAttachmentDescription att = desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR);
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &ref;
  for (uint32_t mask : {0x3Fu, 0x40u}) {
    VkRenderPassMultiviewCreateInfo mv{VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO};
    mv.subpassCount = 1;
    mv.pViewMasks = &mask;
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, &mv};
    ci.attachmentCount = 1;
    ci.pAttachments = &att;
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    VkRenderPass rp = VK_NULL_HANDLE;
    if (mask == 0x3F) {
      EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_SUCCESS);
      EXPECT_TRUE(vkrtMessages().empty());
      vkDestroyRenderPass(device, rp, nullptr);
    } else {
      EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_ERROR_VALIDATION_FAILED_EXT);
      expectVkrtMessage("VUID-VkRenderPassMultiviewCreateInfo-pViewMasks-06697");
    }
  }
  VkAttachmentDescription2 att2{VK_STRUCTURE_TYPE_ATTACHMENT_DESCRIPTION_2};
  att2.format = kFormat;
  att2.samples = VK_SAMPLE_COUNT_1_BIT;
  att2.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att2.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att2.initialLayout = att2.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
  VkAttachmentReference2 ref2{VK_STRUCTURE_TYPE_ATTACHMENT_REFERENCE_2, nullptr, 0, VK_IMAGE_LAYOUT_GENERAL,
                              VK_IMAGE_ASPECT_COLOR_BIT};
  for (uint32_t mask : {0x3Fu, 0x41u}) {
    VkSubpassDescription2 sub2{VK_STRUCTURE_TYPE_SUBPASS_DESCRIPTION_2};
    sub2.viewMask = mask;
    sub2.colorAttachmentCount = 1;
    sub2.pColorAttachments = &ref2;
    VkRenderPassCreateInfo2 ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO_2};
    ci.attachmentCount = 1;
    ci.pAttachments = &att2;
    ci.subpassCount = 1;
    ci.pSubpasses = &sub2;
    VkRenderPass rp = VK_NULL_HANDLE;
    if (mask == 0x3F) {
      EXPECT_EQ(vkCreateRenderPass2(device, &ci, nullptr, &rp), VK_SUCCESS);
      EXPECT_TRUE(vkrtMessages().empty());
      vkDestroyRenderPass(device, rp, nullptr);
    } else {
      EXPECT_EQ(vkCreateRenderPass2(device, &ci, nullptr, &rp), VK_ERROR_VALIDATION_FAILED_EXT);
      expectVkrtMessage("VUID-VkSubpassDescription2-viewMask-06706");
    }
  }
}

// VUID-VkFramebufferCreateInfo-renderPass-04536: a view mask of 0b11 needs two layers in each attachment (the two
// layer view is accepted in MultiviewTest.RenderPassTwoViews).
TEST_F(MultiviewMisuseTest, FramebufferAttachmentLacksViewLayers) {
  Attachment one = attachment(kFormat, kW, kH, 1), two = attachment(kFormat, kW, kH, 2);
  VkRenderPass rp = multiviewPass(0b11);
  VkFramebufferCreateInfo ci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  ci.renderPass = rp;
  ci.attachmentCount = 1;
  ci.pAttachments = &one.view;
  ci.width = kW;
  ci.height = kH;
  ci.layers = 1;
  VkFramebuffer fb = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkFramebufferCreateInfo-renderPass-04536");
  ci.pAttachments = &two.view;
  EXPECT_EQ(vkCreateFramebuffer(device, &ci, nullptr, &fb), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(one);
  destroy(two);
}

// VUID-VkRenderingInfo-viewMask-06128 and VkGraphicsPipelineCreateInfo-renderPass-06578: view indices below
// maxMultiviewViewCount in vkCmdBeginRendering and in pipelines for dynamic rendering.
TEST_F(MultiviewMisuseTest, DynamicRenderingViewMaskPastMaxViewCount) {
  PipelineDesc d;
  d.vs = kSpv_multiview_vert;
  d.vsBytes = sizeof kSpv_multiview_vert;
  d.fs = kSpv_multiview_frag;
  d.fsBytes = sizeof kSpv_multiview_frag;
  d.viewMask = 0x40;
  VkPipeline p;
  EXPECT_EQ(pipeline(d, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-renderPass-06578");
  d.viewMask = 0x20;
  EXPECT_EQ(pipeline(d, &p), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());

  Attachment a = attachment(kFormat, kW, kH, 6);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = a.view;
  color.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {kW, kH}};
  ri.layerCount = 1;
  ri.viewMask = 0x40;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &color;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-VkRenderingInfo-viewMask-06128");
  ri.viewMask = 0x20;
  vkCmdBeginRendering(cb, &ri);
  EXPECT_TRUE(vkrtMessages().empty());
  vkCmdEndRendering(cb);
  submitAndWait(cb);
  destroy(a);
}

// ---- the rules without the multiview feature ----

class MultiviewDisabledTest : public MultiviewTest {
 protected:
  bool multiview() const override { return false; }
  bool validation() const override { return false; }
};

// VUID-VkRenderPassMultiviewCreateInfo-multiview-06555, VkSubpassDescription2-multiview-06558,
// VkRenderingInfo-multiview-06127, VkGraphicsPipelineCreateInfo-multiview-06577: view masks need the feature (the
// same calls succeed with it enabled: MultiviewTest).
TEST_F(MultiviewDisabledTest, ViewMasksNeedTheFeature) {
  VkAttachmentDescription att = desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR);
  VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &ref;
  const uint32_t mask = 0b11;
  VkRenderPassMultiviewCreateInfo mv{VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO};
  mv.subpassCount = 1;
  mv.pViewMasks = &mask;
  VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, &mv};
  ci.attachmentCount = 1;
  ci.pAttachments = &att;
  ci.subpassCount = 1;
  ci.pSubpasses = &sub;
  VkRenderPass rp = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkRenderPassMultiviewCreateInfo-multiview-06555");

  VkAttachmentDescription2 att2{VK_STRUCTURE_TYPE_ATTACHMENT_DESCRIPTION_2};
  att2.format = kFormat;
  att2.samples = VK_SAMPLE_COUNT_1_BIT;
  att2.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  att2.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  att2.initialLayout = att2.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
  VkAttachmentReference2 ref2{VK_STRUCTURE_TYPE_ATTACHMENT_REFERENCE_2, nullptr, 0, VK_IMAGE_LAYOUT_GENERAL,
                              VK_IMAGE_ASPECT_COLOR_BIT};
  VkSubpassDescription2 sub2{VK_STRUCTURE_TYPE_SUBPASS_DESCRIPTION_2};
  sub2.viewMask = mask;
  sub2.colorAttachmentCount = 1;
  sub2.pColorAttachments = &ref2;
  VkRenderPassCreateInfo2 ci2{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO_2};
  ci2.attachmentCount = 1;
  ci2.pAttachments = &att2;
  ci2.subpassCount = 1;
  ci2.pSubpasses = &sub2;
  EXPECT_EQ(vkCreateRenderPass2(device, &ci2, nullptr, &rp), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubpassDescription2-multiview-06558");

  PipelineDesc d;
  d.vs = kSpv_multiview_vert;
  d.vsBytes = sizeof kSpv_multiview_vert;
  d.fs = kSpv_multiview_frag;
  d.fsBytes = sizeof kSpv_multiview_frag;
  d.viewMask = mask;
  VkPipeline p;
  EXPECT_EQ(pipeline(d, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-multiview-06577");

  Attachment a = attachment(kFormat, kW, kH, 2);
  VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  color.imageView = a.view;
  color.imageLayout = VK_IMAGE_LAYOUT_GENERAL;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {kW, kH}};
  ri.layerCount = 1;
  ri.viewMask = mask;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &color;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-VkRenderingInfo-multiview-06127");
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  destroy(a);
}

}  // namespace
}  // namespace vkrt::test
