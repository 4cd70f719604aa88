// Input attachments: a subpass reads what an earlier subpass wrote (subpassLoad at the fragment's own position,
// VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT descriptors), single-sample, multisampled (subpassInputMS with a Sample
// operand) and per view with multiview; the descriptor rules vkrt checks for the type, both sides.
#include "e2e/subpass_fixture.hpp"
#include "multiview.frag.spv.h"
#include "multiview.vert.spv.h"
#include "multiview_input.frag.spv.h"
#include "subpass_depth_quad.vert.spv.h"
#include "subpass_gradient.frag.spv.h"
#include "subpass_input.frag.spv.h"
#include "subpass_input_ms.frag.spv.h"
#include "subpass_quad.vert.spv.h"
#include "subpass_read_depth.frag.spv.h"
#include "subpass_sample_id.frag.spv.h"

namespace vkrt::test {
namespace {

class InputAttachmentTest : public SubpassTest {
 protected:
  // A set layout of one input attachment at binding 0 for the fragment stage, a pool and a set with `view` in it.
  struct InputSet {
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
  };
  InputSet inputSet(VkImageView view) {
    InputSet s;
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.bindingCount = 1;
    lci.pBindings = &b;
    EXPECT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &s.layout), VK_SUCCESS);
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, 1};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 1;
    pci.pPoolSizes = &size;
    EXPECT_EQ(vkCreateDescriptorPool(device, &pci, nullptr, &s.pool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = s.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &s.layout;
    EXPECT_EQ(vkAllocateDescriptorSets(device, &ai, &s.set), VK_SUCCESS);
    VkDescriptorImageInfo ii{VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = s.set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    return s;
  }
  void destroy(InputSet& s) {
    vkDestroyDescriptorPool(device, s.pool, nullptr);
    vkDestroyDescriptorSetLayout(device, s.layout, nullptr);
  }
  using SubpassTest::destroy;

  // Two subpasses: 0 writes attachment 0 (A), 1 reads A as input attachment 0 and writes attachment 1 (B); a
  // BY_REGION dependency from A's writes to its input reads. `masks`: view masks of both subpasses (0: none).
  VkRenderPass twoSubpasses(VkSampleCountFlagBits samplesA, uint32_t mask) {
    VkAttachmentDescription atts[2] = {desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR, samplesA),
                                       desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR)};
    VkAttachmentReference a{0, VK_IMAGE_LAYOUT_GENERAL}, bRef{1, VK_IMAGE_LAYOUT_GENERAL};
    VkSubpassDescription subs[2]{};
    subs[0].pipelineBindPoint = subs[1].pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subs[0].colorAttachmentCount = 1;
    subs[0].pColorAttachments = &a;
    subs[1].inputAttachmentCount = 1;
    subs[1].pInputAttachments = &a;
    subs[1].colorAttachmentCount = 1;
    subs[1].pColorAttachments = &bRef;
    VkSubpassDependency dep{};
    dep.srcSubpass = 0;
    dep.dstSubpass = 1;
    dep.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep.dstStageMask = VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT;
    dep.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    dep.dstAccessMask = VK_ACCESS_INPUT_ATTACHMENT_READ_BIT;
    dep.dependencyFlags = VK_DEPENDENCY_BY_REGION_BIT | (mask ? VK_DEPENDENCY_VIEW_LOCAL_BIT : 0);
    const uint32_t masks[2] = {mask, mask};
    VkRenderPassMultiviewCreateInfo mv{VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO};
    mv.subpassCount = 2;
    mv.pViewMasks = masks;
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, mask ? &mv : nullptr};
    ci.attachmentCount = 2;
    ci.pAttachments = atts;
    ci.subpassCount = 2;
    ci.pSubpasses = subs;
    ci.dependencyCount = 1;
    ci.pDependencies = &dep;
    VkRenderPass rp = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateRenderPass(device, &ci, nullptr, &rp), VK_SUCCESS);
    return rp;
  }

  struct Shaders {
    const uint32_t *vs0, *fs0, *vs1, *fs1;
    size_t vs0Bytes, fs0Bytes, vs1Bytes, fs1Bytes;
  };

  // Runs the two subpasses (6 vertices each) with A and B cleared to transparent black.
  void run(VkRenderPass rp, VkFramebuffer fb, const Shaders& s, VkImageView inputView, VkSampleCountFlagBits samplesA,
           bool sampleShading0) {
    InputSet set = inputSet(inputView);
    PipelineDesc d0;
    d0.vs = s.vs0, d0.vsBytes = s.vs0Bytes, d0.fs = s.fs0, d0.fsBytes = s.fs0Bytes;
    d0.renderPass = rp;
    d0.samples = samplesA;
    d0.sampleShading = sampleShading0;
    PipelineDesc d1;
    d1.vs = s.vs1, d1.vsBytes = s.vs1Bytes, d1.fs = s.fs1, d1.fsBytes = s.fs1Bytes;
    d1.renderPass = rp;
    d1.subpass = 1;
    d1.layout = pipelineLayout(set.layout);
    VkPipeline p0, p1;
    ASSERT_EQ(pipeline(d0, &p0), VK_SUCCESS);
    ASSERT_EQ(pipeline(d1, &p1), VK_SUCCESS);
    VkClearValue clear{};
    VkRenderPassBeginInfo bi = beginInfo(rp, fb, {{0, 0}, {kW, kH}}, {clear, clear});
    VkCommandBuffer cb = beginOneTime();
    vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p0);
    vkCmdDraw(cb, 6, 1, 0, 0);
    vkCmdNextSubpass(cb, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p1);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, d1.layout, 0, 1, &set.set, 0, nullptr);
    vkCmdDraw(cb, 6, 1, 0, 0);
    vkCmdEndRenderPass(cb);
    submitAndWait(cb);
    destroy(set);
  }

  // Compares layer `layer` of `a` with want(x, y); returns the mismatches (the first few logged).
  template <class F>
  int compare(const Attachment& a, uint32_t layer, F want) {
    std::vector<uint8_t> px = readBack(a, VK_IMAGE_ASPECT_COLOR_BIT, 4, layer);
    int bad = 0;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const uint32_t got = texelU32(px, y * kW + x), w = want(x, y);
        if (!near(got, w) && bad++ < 4)
          ADD_FAILURE() << "layer " << layer << " pixel (" << x << ", " << y << "): 0x" << std::hex << got
                        << ", expected 0x" << w;
      }
    return bad;
  }
  static double unorm(uint32_t texel, int c) { return double((texel >> (8 * c)) & 0xFF) / 255.0; }
};

// Subpass 0 writes a gradient to A ((x + 0.5) / 32, (y + 0.5) / 32, 0.5, 1 at pixel centres); subpass 1 reads A
// at each fragment and writes (1 - r, g / 2, b, 1) to B: B is that function of A's stored (8-bit) texels.
TEST_F(InputAttachmentTest, SecondSubpassReadsFirstSubpassOutput) {
  Attachment a = attachment(kFormat, kW, kH, 1, VK_SAMPLE_COUNT_1_BIT, VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT);
  Attachment b = attachment(kFormat, kW, kH);
  VkRenderPass rp = twoSubpasses(VK_SAMPLE_COUNT_1_BIT, 0);
  VkFramebuffer fb = framebuffer(rp, {a.view, b.view}, kW, kH);
  run(rp, fb,
      {kSpv_subpass_quad_vert, kSpv_subpass_gradient_frag, kSpv_subpass_quad_vert, kSpv_subpass_input_frag,
       sizeof kSpv_subpass_quad_vert, sizeof kSpv_subpass_gradient_frag, sizeof kSpv_subpass_quad_vert,
       sizeof kSpv_subpass_input_frag},
      a.view, VK_SAMPLE_COUNT_1_BIT, false);
  auto gradient = [](uint32_t x, uint32_t y) { return rgba8((x + 0.5) / 32, (y + 0.5) / 32, 0.5, 1); };
  EXPECT_EQ(compare(a, 0, gradient), 0);
  EXPECT_EQ(compare(b, 0,
                    [&](uint32_t x, uint32_t y) {
                      const uint32_t t = gradient(x, y);
                      return rgba8(1 - unorm(t, 0), unorm(t, 1) / 2, unorm(t, 2), 1);
                    }),
            0);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
  destroy(b);
}

// The depth attachment read as an input attachment in its own subpass, between two draws ordered by a barrier (the
// subpass's self-dependency): the second draw's shader reads the first draw's depth, 0.25, not its own 0.75. A
// shader that reads input attachments runs before the depth test writes (as late tests); before, vkrt ran the tests
// early for shaders without side effects, so the shader read its own depth (CTS
// rasterization.rasterization_order_attachment_access.{depth,stencil}.*.multi_draw_barriers).
TEST_F(InputAttachmentTest, ADepthFeedbackLoopReadsThePreviousDrawsDepth) {
  const VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;
  Attachment color = attachment(kFormat, kW, kH);
  Attachment depth = attachment(depthFormat, kW, kH, 1, VK_SAMPLE_COUNT_1_BIT, VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT);
  const VkAttachmentReference colorRef{0, VK_IMAGE_LAYOUT_GENERAL}, depthRef{1, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 1;
  sub.pColorAttachments = &colorRef;
  sub.pDepthStencilAttachment = &depthRef;
  sub.inputAttachmentCount = 1;
  sub.pInputAttachments = &depthRef;
  const VkAttachmentDescription atts[2] = {desc(kFormat, VK_ATTACHMENT_LOAD_OP_CLEAR),
                                           desc(depthFormat, VK_ATTACHMENT_LOAD_OP_CLEAR)};
  VkSubpassDependency self{0,
                           0,
                           VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                           VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                           VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                           VK_ACCESS_INPUT_ATTACHMENT_READ_BIT,
                           VK_DEPENDENCY_BY_REGION_BIT};
  VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  rci.attachmentCount = 2;
  rci.pAttachments = atts;
  rci.subpassCount = 1;
  rci.pSubpasses = &sub;
  rci.dependencyCount = 1;
  rci.pDependencies = &self;
  VkRenderPass rp = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateRenderPass(device, &rci, nullptr, &rp), VK_SUCCESS);
  VkFramebuffer fb = framebuffer(rp, {color.view, depth.view}, kW, kH);
  InputSet set = inputSet(depth.view);
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT, 0, 4};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = 1;
  lci.pSetLayouts = &set.layout;
  lci.pushConstantRangeCount = 1;
  lci.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = ds.depthWriteEnable = VK_TRUE;
  ds.depthCompareOp = VK_COMPARE_OP_ALWAYS;
  PipelineDesc pd;
  pd.vs = kSpv_subpass_depth_quad_vert;
  pd.vsBytes = sizeof kSpv_subpass_depth_quad_vert;
  pd.fs = kSpv_subpass_read_depth_frag;
  pd.fsBytes = sizeof kSpv_subpass_read_depth_frag;
  pd.renderPass = rp;
  pd.layout = layout;
  pd.depthStencil = &ds;
  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(this->pipeline(pd, &pipeline), VK_SUCCESS);

  VkClearValue clears[2]{};
  clears[1].depthStencil = {0.5f, 0};
  VkRenderPassBeginInfo bi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  bi.renderPass = rp;
  bi.framebuffer = fb;
  bi.renderArea = {{0, 0}, {kW, kH}};
  bi.clearValueCount = 2;
  bi.pClearValues = clears;
  VkCommandBuffer cb = beginOneTime();
  vkCmdBeginRenderPass(cb, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, 0, 1, &set.set, 0, nullptr);
  for (float z : {0.25f, 0.75f}) {
    if (z != 0.25f) {
      VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
      b.srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
      b.dstAccessMask = VK_ACCESS_INPUT_ATTACHMENT_READ_BIT;
      b.oldLayout = b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
      b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      b.image = depth.img.image;
      b.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
      vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                           VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_DEPENDENCY_BY_REGION_BIT, 0, nullptr, 0, nullptr,
                           1, &b);
    }
    vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_VERTEX_BIT, 0, 4, &z);
    vkCmdDraw(cb, 6, 1, 0, 0);
  }
  vkCmdEndRenderPass(cb);
  submitAndWait(cb);
  // The second draw wrote the depth the first left (0.25); the depth attachment holds the second's (0.75).
  EXPECT_EQ(compare(color, 0, [](uint32_t, uint32_t) { return rgba8(0.25, 0, 0, 1); }), 0);
  const std::vector<uint8_t> d = readBack(depth, VK_IMAGE_ASPECT_DEPTH_BIT, 4);
  float d0;
  std::memcpy(&d0, d.data(), 4);
  EXPECT_EQ(d0, 0.75f);
  vkDestroyPipelineLayout(device, layout, nullptr);
  destroy(set);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(color);
  destroy(depth);
}

// A has 4 samples, each written by its own invocation with red 0.2 (sample + 1); subpass 1 (one sample) reads
// sample 3 (subpassLoad(inA, 3)): red 0.8 everywhere.
TEST_F(InputAttachmentTest, MultisampledInputReadsTheNamedSample) {
  Attachment a = attachment(kFormat, kW, kH, 1, VK_SAMPLE_COUNT_4_BIT, VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT);
  Attachment b = attachment(kFormat, kW, kH);
  VkRenderPass rp = twoSubpasses(VK_SAMPLE_COUNT_4_BIT, 0);
  VkFramebuffer fb = framebuffer(rp, {a.view, b.view}, kW, kH);
  run(rp, fb,
      {kSpv_subpass_quad_vert, kSpv_subpass_sample_id_frag, kSpv_subpass_quad_vert, kSpv_subpass_input_ms_frag,
       sizeof kSpv_subpass_quad_vert, sizeof kSpv_subpass_sample_id_frag, sizeof kSpv_subpass_quad_vert,
       sizeof kSpv_subpass_input_ms_frag},
      a.view, VK_SAMPLE_COUNT_4_BIT, true);
  EXPECT_EQ(compare(b, 0, [](uint32_t, uint32_t) { return rgba8(0.2 * 4, 0.5, 0, 1); }), 0);
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
  destroy(b);
}

// Multiview: both subpasses have view mask 0b11; subpass 0 draws the multiview rectangle (view v: columns
// [16 v, 16 v + 16), red 1 in view 0, green 1 in view 1) into A's layer v, subpass 1 reads A in each view (its own
// layer) and writes (r, g, 0.25 (v + 1), 1) to B's layer v.
TEST_F(InputAttachmentTest, EachViewReadsItsOwnLayer) {
  Attachment a = attachment(kFormat, kW, kH, 2, VK_SAMPLE_COUNT_1_BIT, VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT);
  Attachment b = attachment(kFormat, kW, kH, 2);
  VkRenderPass rp = twoSubpasses(VK_SAMPLE_COUNT_1_BIT, 0b11);
  VkFramebuffer fb = framebuffer(rp, {a.view, b.view}, kW, kH);
  run(rp, fb,
      {kSpv_multiview_vert, kSpv_multiview_frag, kSpv_subpass_quad_vert, kSpv_multiview_input_frag,
       sizeof kSpv_multiview_vert, sizeof kSpv_multiview_frag, sizeof kSpv_subpass_quad_vert,
       sizeof kSpv_multiview_input_frag},
      a.view, VK_SAMPLE_COUNT_1_BIT, false);
  for (uint32_t v = 0; v < 2; ++v) {
    EXPECT_EQ(compare(b, v,
                      [&](uint32_t x, uint32_t) {
                        const bool inside = x >= 16 * v && x < 16 * v + 16;
                        return rgba8(inside && v == 0, inside && v == 1, 0.25 * (v + 1), 1);
                      }),
              0);
  }
  vkDestroyFramebuffer(device, fb, nullptr);
  vkDestroyRenderPass(device, rp, nullptr);
  destroy(a);
  destroy(b);
}

TEST_F(InputAttachmentTest, LimitsAtLeastTheRequiredMinimums) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(physicalDevice, &p);
  EXPECT_GE(p.limits.maxPerStageDescriptorInputAttachments, 4u);  // the spec's required limits
  EXPECT_GE(p.limits.maxDescriptorSetInputAttachments, 4u);
}

class InputAttachmentMisuseTest : public InputAttachmentTest {
 protected:
  bool validation() const override { return false; }
};

// VUID-VkDescriptorSetLayoutBinding-descriptorType-01510: input attachments are for fragment shaders only (the
// fragment-stage binding is accepted: InputAttachmentTest). VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-
// None-03011: they cannot be update-after-bind.
TEST_F(InputAttachmentMisuseTest, LayoutBindingRules) {
  VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_INPUT_ATTACHMENT, 1, VK_SHADER_STAGE_VERTEX_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = 1;
  lci.pBindings = &b;
  VkDescriptorSetLayout l = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &l), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutBinding-descriptorType-01510");
  b.stageFlags = 0;  // 0 is allowed too
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &l), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyDescriptorSetLayout(device, l, nullptr);

  b.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
  const VkDescriptorBindingFlags flags = VK_DESCRIPTOR_BINDING_UPDATE_AFTER_BIND_BIT;
  VkDescriptorSetLayoutBindingFlagsCreateInfo bf{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_BINDING_FLAGS_CREATE_INFO};
  bf.bindingCount = 1;
  bf.pBindingFlags = &flags;
  lci.pNext = &bf;
  lci.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_UPDATE_AFTER_BIND_POOL_BIT;
  EXPECT_EQ(vkCreateDescriptorSetLayout(device, &lci, nullptr, &l), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkDescriptorSetLayoutBindingFlagsCreateInfo-None-03011");
}

}  // namespace
}  // namespace vkrt::test
