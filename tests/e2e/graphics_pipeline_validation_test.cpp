// vkCreateGraphicsPipelines' rules, both sides: each misuse is refused with vkrt's report naming the VUID (the
// validation layer is off: it would report the same misuse), and the corrected create info succeeds silently.
// Also VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT and pipeline derivatives.
#include "e2e/draw_fixture.hpp"

#include "draw_color.frag.spv.h"
#include "draw_color.vert.spv.h"

namespace vkrt::test {
namespace {

class GraphicsPipelineValidationTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.validation = false;
    o.pipelineCreationCacheControl = true;
    return o;
  }
  PipelineDesc valid() {
    PipelineDesc d;
    d.vs = kSpv_draw_color_vert;
    d.vsBytes = sizeof kSpv_draw_color_vert;
    d.fs = kSpv_draw_color_frag;
    d.fsBytes = sizeof kSpv_draw_color_frag;
    d.bindings = {{0, 24, VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R8G8B8A8_UNORM, 8}};
    return d;
  }
  // A vertex-shader-only pipeline (draw_color.vert, no blending state used) with the given rendering info.
  VkResult createWithRendering(const PipelineDesc& d, const VkPipelineRenderingCreateInfo& ri, VkPipeline* out) {
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = d.vsBytes;
    sm.pCode = d.vs;
    VkShaderModule m;
    EXPECT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
    modules.push_back(m);
    if (!layout) {
      VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
      EXPECT_EQ(vkCreatePipelineLayout(device, &lci, nullptr, &layout), VK_SUCCESS);
    }
    VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stage.stage = VK_SHADER_STAGE_VERTEX_BIT;
    stage.module = m;
    stage.pName = "main";
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vi.vertexBindingDescriptionCount = uint32_t(d.bindings.size());
    vi.pVertexBindingDescriptions = d.bindings.data();
    vi.vertexAttributeDescriptionCount = uint32_t(d.attributes.size());
    vi.pVertexAttributeDescriptions = d.attributes.data();
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = vp.scissorCount = 1;
    vp.pViewports = &d.viewport;
    vp.pScissors = &d.scissor;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = 1;
    cb.pAttachments = &d.blend;
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO, &ri};
    ci.stageCount = 1;
    ci.pStages = &stage;
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &ds;
    ci.pColorBlendState = &cb;
    ci.layout = layout;
    ci.basePipelineIndex = -1;
    *out = VK_NULL_HANDLE;
    return vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, out);
  }
  // Expects `bad` to be refused with `vuid` and `good` to succeed without a report.
  void expectBoth(const PipelineDesc& bad, const PipelineDesc& good, const char* vuid) {
    VkPipeline p;
    EXPECT_EQ(createPipeline(bad, &p), VK_ERROR_VALIDATION_FAILED_EXT) << vuid;
    EXPECT_EQ(p, VK_NULL_HANDLE);
    expectVkrtMessage(vuid);
    EXPECT_EQ(createPipeline(good, &p), VK_SUCCESS) << vuid;
    EXPECT_TRUE(vkrtMessages().empty()) << (vkrtMessages().empty() ? "" : vkrtMessages()[0].text);
    vkDestroyPipeline(device, p, nullptr);
  }
};

TEST_F(GraphicsPipelineValidationTest, ValidPipelineWithEveryDynamicState) {
  PipelineDesc d = valid();
  d.dynamic = {VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT,
               VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT,
               VK_DYNAMIC_STATE_LINE_WIDTH,
               VK_DYNAMIC_STATE_DEPTH_BIAS,
               VK_DYNAMIC_STATE_BLEND_CONSTANTS,
               VK_DYNAMIC_STATE_DEPTH_BOUNDS,
               VK_DYNAMIC_STATE_STENCIL_COMPARE_MASK,
               VK_DYNAMIC_STATE_STENCIL_WRITE_MASK,
               VK_DYNAMIC_STATE_STENCIL_REFERENCE,
               VK_DYNAMIC_STATE_CULL_MODE,
               VK_DYNAMIC_STATE_FRONT_FACE,
               VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY,
               VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE,
               VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE,
               VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE,
               VK_DYNAMIC_STATE_DEPTH_COMPARE_OP,
               VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE,
               VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE,
               VK_DYNAMIC_STATE_STENCIL_OP,
               VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE,
               VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE,
               VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE};
  VkPipeline p;
  EXPECT_EQ(createPipeline(d, &p), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, p, nullptr);
}

TEST_F(GraphicsPipelineValidationTest, VertexInputBindingsAndAttributes) {
  PipelineDesc bad = valid();
  bad.bindings.push_back({0, 16, VK_VERTEX_INPUT_RATE_INSTANCE});
  PipelineDesc good = valid();
  good.bindings.push_back({1, 16, VK_VERTEX_INPUT_RATE_INSTANCE});
  expectBoth(bad, good, "VUID-VkPipelineVertexInputStateCreateInfo-pVertexBindingDescriptions-00616");

  bad = valid();
  bad.attributes[1].location = 0;
  expectBoth(bad, valid(), "VUID-VkPipelineVertexInputStateCreateInfo-pVertexAttributeDescriptions-00617");

  bad = valid();
  bad.attributes[1].binding = 3;
  good = valid();
  good.bindings.push_back({3, 4, VK_VERTEX_INPUT_RATE_VERTEX});
  good.attributes[1].binding = 3;
  expectBoth(bad, good, "VUID-VkPipelineVertexInputStateCreateInfo-binding-00615");

  bad = valid();
  bad.attributes[1].format = VK_FORMAT_R8G8B8A8_SRGB;  // no VERTEX_BUFFER_BIT
  expectBoth(bad, valid(), "VUID-VkVertexInputAttributeDescription-format-00623");

  bad = valid();
  bad.attributes[1].offset = 4096;
  expectBoth(bad, valid(), "VUID-VkVertexInputAttributeDescription-offset-00622");

  bad = valid();
  bad.bindings[0].binding = 32;
  bad.attributes[0].binding = bad.attributes[1].binding = 32;
  expectBoth(bad, valid(), "VUID-VkVertexInputBindingDescription-binding-00618");
}

TEST_F(GraphicsPipelineValidationTest, ShaderStages) {
  // A geometry shader stage (the geometryShader feature is not supported): the stage is refused before its module
  // is looked at.
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = sizeof kSpv_draw_color_vert;
  sm.pCode = kSpv_draw_color_vert;
  VkShaderModule m;
  ASSERT_EQ(vkCreateShaderModule(device, &sm, nullptr, &m), VK_SUCCESS);
  modules.push_back(m);
  VkPipelineShaderStageCreateInfo geom{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  geom.stage = VK_SHADER_STAGE_GEOMETRY_BIT;
  geom.module = m;
  geom.pName = "main";
  PipelineDesc bad = valid();
  bad.extraStages.push_back(geom);
  expectBoth(bad, valid(), "VUID-VkPipelineShaderStageCreateInfo-stage-00704");

  // No vertex shader.
  bad = valid();
  bad.vs = nullptr;
  expectBoth(bad, valid(), "VUID-VkGraphicsPipelineCreateInfo-stage-02096");

  // A vertex stage whose module has no Vertex entry point of that name.
  bad = valid();
  bad.vs = kSpv_draw_color_frag;
  bad.vsBytes = sizeof kSpv_draw_color_frag;
  expectBoth(bad, valid(), "VUID-VkPipelineShaderStageCreateInfo-pName-00707");

  // The fragment shader is optional.
  PipelineDesc noFragment = valid();
  noFragment.fs = nullptr;
  VkPipeline p;
  EXPECT_EQ(createPipeline(noFragment, &p), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, p, nullptr);
}

TEST_F(GraphicsPipelineValidationTest, DynamicStates) {
  PipelineDesc bad = valid();
  bad.dynamic = {VK_DYNAMIC_STATE_CULL_MODE, VK_DYNAMIC_STATE_CULL_MODE};
  PipelineDesc good = valid();
  good.dynamic = {VK_DYNAMIC_STATE_CULL_MODE};
  expectBoth(bad, good, "VUID-VkPipelineDynamicStateCreateInfo-pDynamicStates-01442");

  bad = valid();
  bad.dynamic = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT};
  good = valid();
  good.dynamic = {VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT};
  expectBoth(bad, good, "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04132");

  bad = valid();
  bad.dynamic = {VK_DYNAMIC_STATE_LOGIC_OP_EXT};
  expectBoth(bad, valid(), "VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04869");
}

TEST_F(GraphicsPipelineValidationTest, RenderingInfoColorCountMatchesBlendState) {
  PipelineDesc bad = valid();
  bad.blendCount = 2;
  PipelineDesc good = valid();
  good.blendCount = 2;
  good.colorCount = 2;
  expectBoth(bad, good, "VUID-VkGraphicsPipelineCreateInfo-renderPass-06055");
  // Without color attachments pColorBlendState is ignored, whatever its count (a depth-only pipeline with one blend
  // attachment state, as the CTS's draw.dynamic_rendering.* depth-only cases create; vkrt reported 06055 for them).
  PipelineDesc depthOnly = valid();
  depthOnly.colorCount = 0;
  depthOnly.blendCount = 1;
  depthOnly.withDepthStencil = true;
  expectBoth(bad, depthOnly, "VUID-VkGraphicsPipelineCreateInfo-renderPass-06055");
}

TEST_F(GraphicsPipelineValidationTest, RenderingInfoDepthStencilFormats) {
  // The fixture names depthStencilFormat() as both the depth and the stencil format; a color format as depth is
  // refused.
  PipelineDesc good = valid();
  good.withDepthStencil = true;
  VkPipeline p;
  EXPECT_EQ(createPipeline(good, &p), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, p, nullptr);
  // A depth format without stencil as the stencil format.
  PipelineDesc d = valid();
  d.fs = nullptr;
  VkPipelineRenderingCreateInfo ri{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
  ri.colorAttachmentCount = 1;
  const VkFormat colorFormat = kColorFormat;
  ri.pColorAttachmentFormats = &colorFormat;
  ri.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
  ri.stencilAttachmentFormat = VK_FORMAT_D32_SFLOAT;
  EXPECT_EQ(createWithRendering(d, ri, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-renderPass-06588");
  ri.depthAttachmentFormat = VK_FORMAT_R8G8B8A8_UNORM;
  ri.stencilAttachmentFormat = VK_FORMAT_UNDEFINED;
  EXPECT_EQ(createWithRendering(d, ri, &p), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-renderPass-06587");
  ri.depthAttachmentFormat = VK_FORMAT_D32_SFLOAT;
  EXPECT_EQ(createWithRendering(d, ri, &p), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, p, nullptr);
}

TEST_F(GraphicsPipelineValidationTest, InputAssemblyAndRasterization) {
  PipelineDesc bad = valid();
  bad.topology = VK_PRIMITIVE_TOPOLOGY_PATCH_LIST;
  expectBoth(bad, valid(), "VUID-VkPipelineInputAssemblyStateCreateInfo-topology-00430");

  bad = valid();
  bad.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  bad.primitiveRestart = VK_TRUE;
  PipelineDesc good = valid();
  good.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
  good.primitiveRestart = VK_TRUE;
  expectBoth(bad, good, "VUID-VkPipelineInputAssemblyStateCreateInfo-topology-06252");
}

TEST_F(GraphicsPipelineValidationTest, Derivatives) {
  VkPipeline base;
  PipelineDesc b = valid();
  ASSERT_EQ(createPipeline(b, &base), VK_SUCCESS);  // without ALLOW_DERIVATIVES
  VkPipeline allowing;
  b.flags = VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT;
  ASSERT_EQ(createPipeline(b, &allowing), VK_SUCCESS);
  PipelineDesc bad = valid();
  bad.flags = VK_PIPELINE_CREATE_DERIVATIVE_BIT;
  bad.base = base;
  PipelineDesc good = bad;
  good.base = allowing;
  expectBoth(bad, good, "VUID-vkCreateGraphicsPipelines-flags-00721");
  vkDestroyPipeline(device, allowing, nullptr);
  vkDestroyPipeline(device, base, nullptr);
}

TEST_F(GraphicsPipelineValidationTest, FailOnCompileRequired) {
  // Each test has a device of its own, whose shader cache starts empty: the first creation would have to compile.
  PipelineDesc d = valid();
  d.flags = VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT;
  VkPipeline p;
  const VkResult first = createPipeline(d, &p);
  EXPECT_EQ(first, VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_EQ(p, VK_NULL_HANDLE);
  EXPECT_TRUE(vkrtMessages().empty());
  d.flags = 0;
  ASSERT_EQ(createPipeline(d, &p), VK_SUCCESS);
  d.flags = VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT;
  VkPipeline again;
  EXPECT_EQ(createPipeline(d, &again), VK_SUCCESS);  // the device holds the code now
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipeline(device, again, nullptr);
  vkDestroyPipeline(device, p, nullptr);
}

}  // namespace
}  // namespace vkrt::test
