// Draws in render pass objects whose subpass uses no color attachment. The pipeline's pColorBlendState may then
// hold any number of attachment states: VUID-VkGraphicsPipelineCreateInfo-renderPass-06042 ties
// attachmentCount to the subpass's colorAttachmentCount only "if the subpass uses color attachments" (the CTS's
// ray_tracing_pipeline.barrier.*_to_frag cases draw so, with one state, in a render pass of no attachment, and
// vkrt skipped their draws under VUID-vkCmdDraw-renderPass-02684). A subpass that uses color attachments still
// needs the counts equal: the draw is reported and skipped.
#include <cstring>

#include "draw_color.vert.spv.h"
#include "draw_count_fragments.frag.spv.h"
#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

class DrawRenderPassTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.features.fragmentStoresAndAtomics = VK_TRUE;
    o.validation = validation_;
    return o;
  }
  void SetUp() override {
    DrawTest::SetUp();
    if (HasFatalFailure() || !device) return;
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.bindingCount = 1;
    lci.pBindings = &b;
    ASSERT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &setLayout_), VK_SUCCESS);
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 1;
    pci.pPoolSizes = &ps;
    ASSERT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &pool_), VK_SUCCESS);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool_;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &setLayout_;
    ASSERT_EQ(vkAllocateDescriptorSets(device, &ai, &set_), VK_SUCCESS);
    counts_ = createHostBuffer(kW * kH * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(counts_.data, 0, kW * kH * 4);
    VkDescriptorBufferInfo bi{counts_.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set_;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  }
  void TearDown() override {
    if (device) {
      destroy(counts_);
      vkDestroyDescriptorPool(device, pool_, nullptr);
      vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    }
    DrawTest::TearDown();
  }

  // A render pass of one subpass using the color attachment `color` (null: no attachment), and its framebuffer.
  void makePass(const Target* color, VkRenderPass* rp, VkFramebuffer* fb) {
    VkAttachmentDescription a{0,
                              kColorFormat,
                              VK_SAMPLE_COUNT_1_BIT,
                              VK_ATTACHMENT_LOAD_OP_CLEAR,
                              VK_ATTACHMENT_STORE_OP_STORE,
                              VK_ATTACHMENT_LOAD_OP_DONT_CARE,
                              VK_ATTACHMENT_STORE_OP_DONT_CARE,
                              VK_IMAGE_LAYOUT_UNDEFINED,
                              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = color ? 1 : 0;
    sub.pColorAttachments = &ref;
    VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rci.attachmentCount = color ? 1 : 0;
    rci.pAttachments = &a;
    rci.subpassCount = 1;
    rci.pSubpasses = &sub;
    ASSERT_EQ(vkCreateRenderPass(device, &rci, nullptr, rp), VK_SUCCESS);
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = *rp;
    fci.attachmentCount = color ? 1 : 0;
    fci.pAttachments = color ? &color->view : nullptr;
    fci.width = kW;
    fci.height = kH;
    fci.layers = 1;
    ASSERT_EQ(vkCreateFramebuffer(device, &fci, nullptr, fb), VK_SUCCESS);
  }

  // Draws two triangles covering the area with a pipeline of `blendCount` blend attachment states in subpass 0 of
  // `rp`; returns the fragment count of each pixel.
  std::vector<uint32_t> drawFullArea(VkRenderPass rp, VkFramebuffer fb, uint32_t blendCount) {
    PipelineDesc d;
    d.vs = kSpv_draw_color_vert;
    d.vsBytes = sizeof kSpv_draw_color_vert;
    d.fs = kSpv_draw_count_fragments_frag;
    d.fsBytes = sizeof kSpv_draw_count_fragments_frag;
    d.bindings = {{0, sizeof(Vertex), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
    d.blendCount = blendCount;
    d.setLayout = setLayout_;
    d.renderPass = rp;
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(createPipeline(d, &p), VK_SUCCESS);
    const Vertex v[6] = {{-1, -1, 1, 0, 0, 1}, {1, -1, 1, 0, 0, 1}, {1, 1, 1, 0, 0, 1},
                         {-1, -1, 1, 0, 0, 1}, {1, 1, 1, 0, 0, 1},  {-1, 1, 1, 0, 0, 1}};
    HostBuffer vb = vertexBuffer(v, sizeof v);
    VkCommandBuffer cb = beginOneTime();
    VkClearValue clear{};
    VkRenderPassBeginInfo bi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    bi.renderPass = rp;
    bi.framebuffer = fb;
    bi.renderArea = {{0, 0}, {kW, kH}};
    bi.clearValueCount = 1;
    bi.pClearValues = &clear;
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set_, 0, nullptr);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &offset);
    vkCmdDraw(cb, 6, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    submitAndWait(cb);
    std::vector<uint32_t> out(kW * kH);
    std::memcpy(out.data(), counts_.data, kW * kH * 4);
    destroy(vb);
    vkDestroyPipeline(device, p, nullptr);
    return out;
  }

  bool validation_ = true;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  HostBuffer counts_;
};

TEST_F(DrawRenderPassTest, ASubpassWithoutAttachmentsShadesEveryPixelWithOneBlendState) {
  VkRenderPass rp = VK_NULL_HANDLE;
  VkFramebuffer fb = VK_NULL_HANDLE;
  makePass(nullptr, &rp, &fb);
  const std::vector<uint32_t> counts = drawFullArea(rp, fb, 1);
  int wrong = 0;
  for (uint32_t i = 0; i < kW * kH; ++i) wrong += counts[i] != 1;
  EXPECT_EQ(wrong, 0) << "pixels not shaded exactly once (pixel 0: " << counts[0] << ")";
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  // (TearDown: neither vkrt nor the validation layer reported anything.)
}

class DrawRenderPassMisuseTest : public DrawRenderPassTest {
 protected:
  void SetUp() override {
    validation_ = false;  // the layer reports the same misuse
    DrawRenderPassTest::SetUp();
  }
};

TEST_F(DrawRenderPassMisuseTest, ASubpassWithAColorAttachmentNeedsAsManyBlendStates) {
  if (!onVkrt()) GTEST_SKIP() << "vkrt's own diagnostics";
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
  VkRenderPass rp = VK_NULL_HANDLE;
  VkFramebuffer fb = VK_NULL_HANDLE;
  makePass(&color, &rp, &fb);
  const std::vector<uint32_t> counts = drawFullArea(rp, fb, 2);
  expectVkrtMessage("VUID-vkCmdDraw-renderPass-02684");
  EXPECT_EQ(counts[0], 0u) << "the draw was skipped";
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(color);
}

}  // namespace
}  // namespace vkrt::test
