// The fixture of the multiview and input attachment tests (multiview_test.cpp, input_attachment_test.cpp): the
// render pass fixture's attachments and read-back, with graphics pipelines for a render pass subpass or for dynamic
// rendering (no vertex input, one color attachment, an optional descriptor set layout), and the multiview feature
// enabled (`multiview` false: not enabled, for the feature's own VUIDs).
#pragma once

#include <cmath>
#include <vector>

#include "e2e/render_pass_fixture.hpp"

namespace vkrt::test {

class SubpassTest : public RenderPassTest {
 protected:
  static constexpr uint32_t kW = 32, kH = 32;
  static constexpr VkFormat kFormat = VK_FORMAT_R8G8B8A8_UNORM;

  virtual bool multiview() const { return true; }
  virtual bool validation() const { return true; }

  FixtureOptions options() override {
    FixtureOptions o = RenderPassTest::options();
    o.validation = validation();
    multiviewFeatures_.multiview = multiview() ? VK_TRUE : VK_FALSE;
    o.featureChain = &multiviewFeatures_;
    o.features.sampleRateShading = VK_TRUE;
    return o;
  }

  struct PipelineDesc {
    const uint32_t* vs = nullptr;
    size_t vsBytes = 0;
    const uint32_t* fs = nullptr;
    size_t fsBytes = 0;
    VkRenderPass renderPass = VK_NULL_HANDLE;  // null: dynamic rendering with `viewMask`
    uint32_t subpass = 0;
    uint32_t viewMask = 0;
    VkSampleCountFlagBits samples = VK_SAMPLE_COUNT_1_BIT;
    bool sampleShading = false;  // minSampleShading 1: one invocation per sample
    VkPipelineLayout layout = VK_NULL_HANDLE;
    const VkPipelineDepthStencilStateCreateInfo* depthStencil = nullptr;
  };

  VkShaderModule module(const uint32_t* words, size_t bytes) {
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    VkShaderModule m = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
    modules_.push_back(m);
    return m;
  }

  VkPipelineLayout pipelineLayout(VkDescriptorSetLayout set = VK_NULL_HANDLE) {
    VkPipelineLayoutCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    ci.setLayoutCount = set ? 1 : 0;
    ci.pSetLayouts = &set;
    VkPipelineLayout l = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreatePipelineLayout(device, &ci, nullptr, &l), VK_SUCCESS);
    layouts_.push_back(l);
    return l;
  }

  // Creates the pipeline (destroyed at TearDown on success); returns vkCreateGraphicsPipelines' result.
  VkResult pipeline(const PipelineDesc& d, VkPipeline* out) {
    VkPipelineShaderStageCreateInfo stages[2]{};
    for (auto& s : stages) {
      s.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
      s.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = module(d.vs, d.vsBytes);
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = module(d.fs, d.fsBytes);
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    const VkViewport viewport{0, 0, float(kW), float(kH), 0, 1};
    const VkRect2D scissor{{0, 0}, {kW, kH}};
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = vp.scissorCount = 1;
    vp.pViewports = &viewport;
    vp.pScissors = &scissor;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = d.samples;
    ms.sampleShadingEnable = d.sampleShading ? VK_TRUE : VK_FALSE;
    ms.minSampleShading = 1.0f;
    VkPipelineColorBlendAttachmentState blend{};
    blend.colorWriteMask = 0xF;
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = 1;
    cb.pAttachments = &blend;
    VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    ri.viewMask = d.viewMask;
    ri.colorAttachmentCount = 1;
    ri.pColorAttachmentFormats = &kFormat;
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.pNext = d.renderPass ? nullptr : &ri;
    ci.stageCount = 2;
    ci.pStages = stages;
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pColorBlendState = &cb;
    ci.pDepthStencilState = d.depthStencil;
    ci.layout = d.layout ? d.layout : pipelineLayout();
    ci.renderPass = d.renderPass;
    ci.subpass = d.subpass;
    *out = VK_NULL_HANDLE;
    VkResult r = vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, out);
    if (r == VK_SUCCESS) pipelines_.push_back(*out);
    return r;
  }

  // RGBA8 of a color given as doubles in [0, 1] (round to nearest), and a per-channel comparison within 1.
  static uint32_t rgba8(double r, double g, double b, double a) {
    auto q = [](double v) { return uint32_t(std::lround(std::fmin(std::fmax(v, 0.0), 1.0) * 255.0)); };
    return q(r) | q(g) << 8 | q(b) << 16 | q(a) << 24;
  }
  static bool near(uint32_t got, uint32_t want) {
    for (int c = 0; c < 4; ++c)
      if (std::abs(int((got >> (8 * c)) & 0xFF) - int((want >> (8 * c)) & 0xFF)) > 1) return false;
    return true;
  }

  void TearDown() override {
    for (VkPipeline p : pipelines_) vkDestroyPipeline(device, p, nullptr);
    for (VkPipelineLayout l : layouts_) vkDestroyPipelineLayout(device, l, nullptr);
    for (VkShaderModule m : modules_) vkDestroyShaderModule(device, m, nullptr);
    RenderPassTest::TearDown();
  }

 private:
  VkPhysicalDeviceMultiviewFeatures multiviewFeatures_{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MULTIVIEW_FEATURES};
  std::vector<VkShaderModule> modules_;
  std::vector<VkPipelineLayout> layouts_;
  std::vector<VkPipeline> pipelines_;
};

}  // namespace vkrt::test
