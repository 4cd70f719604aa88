// Graphics extensions promoted to Vulkan 1.1-1.3 that applications written for older versions enable by name, each
// enabled that way under the validation layer and what it adds drawn (the audit of the extension list:
// promoted_extensions_test.cpp):
// - VK_KHR_shader_draw_parameters: BaseVertex, BaseInstance and DrawIndex in a vertex shader, by the extension's
//   name and by the shaderDrawParameters feature, through direct, indexed and indirect draws;
// - VK_EXT_extended_dynamic_state: the dynamic state of Vulkan 1.3 set through the extension's EXT-named commands;
// - VK_EXT_extended_dynamic_state2: the logic op set by vkCmdSetLogicOpEXT, the feature rules of its two commands;
// - VK_KHR_maintenance2: points clipped by their vertex against the view volume (pointClippingBehavior
//   ALL_CLIP_PLANES), and its structures (input attachment aspects, view usage, the depth/stencil read-only layouts)
//   taken.
#include <array>
#include <cstring>
#include <vector>

#include "draw_color.frag.spv.h"
#include "draw_color.vert.spv.h"
#include "draw_parameters.vert.spv.h"
#include "draw_point.vert.spv.h"
#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

// ---- VK_KHR_shader_draw_parameters

// The parameter: true enables the extension by name, false the shaderDrawParameters feature (Vulkan 1.1).
class DrawParametersTest : public QuadrantDrawTest, public ::testing::WithParamInterface<bool> {
 protected:
  VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    if (GetParam()) {
      o.deviceExtensions = {VK_KHR_SHADER_DRAW_PARAMETERS_EXTENSION_NAME};
    } else {
      f11.shaderDrawParameters = VK_TRUE;
      o.featureChain = &f11;
    }
    return o;
  }
  void SetUp() override {
    DrawTest::SetUp();
    if (HasFatalFailure()) return;
    setUpQuadrants(kSpv_draw_parameters_vert, sizeof kSpv_draw_parameters_vert);
  }
  // Quadrant q's triangle in the color the shader gives these parameters ("Built-In Variables": BaseVertex is
  // firstVertex, or vertexOffset for an indexed draw; BaseInstance firstInstance; DrawIndex the index of the draw in
  // a multi-draw command, else 0).
  std::array<V, 3> expect(int q, int baseVertex, int baseInstance, int drawIndex) {
    std::array<V, 3> t = quads[q];
    for (V& x : t) {
      x.r = float(baseVertex + 8) / 255.0f;
      x.g = float(baseInstance) / 255.0f;
      x.b = float(drawIndex) / 255.0f;
    }
    return t;
  }
};

TEST_P(DrawParametersTest, TheFeatureIsReported) {
  VkPhysicalDeviceShaderDrawParametersFeatures dp{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_DRAW_PARAMETERS_FEATURES};
  VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &dp};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v11};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(dp.shaderDrawParameters);
  EXPECT_TRUE(v11.shaderDrawParameters);
}

TEST_P(DrawParametersTest, DirectAndIndexedDraws) {
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDraw(cb, 3, 1, 3, 5);             // quadrant 1: BaseVertex = firstVertex 3, BaseInstance 5
    vkCmdDrawIndexed(cb, 3, 1, 0, 6, 2);   // indices 0..2 + 6: quadrant 2, BaseVertex = vertexOffset 6
    vkCmdDrawIndexed(cb, 3, 1, 9, -9, 4);  // indices 9..11 - 9: quadrant 0, BaseVertex -9
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(1, 3, 5, 0), expect(2, 6, 2, 0), expect(0, -9, 4, 0)}, 0, false), 0);
}

TEST_P(DrawParametersTest, IndirectDrawsCountTheirDrawIndex) {
  const VkDrawIndirectCommand cmds[2] = {{3, 1, 9, 7}, {3, 1, 0, 1}};  // quadrants 3 and 0
  const VkDrawIndexedIndirectCommand icmds[3] = {
      {3, 1, 3, 0, 3}, {3, 1, 0, 6, 9}, {3, 1, 9, 0, 0}};  // quadrants 1, 2 (and 3, beyond the count)
  HostBuffer args = vertexBuffer(cmds, sizeof cmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  HostBuffer iargs = vertexBuffer(icmds, sizeof icmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  const uint32_t two = 2;
  HostBuffer count = vertexBuffer(&two, 4, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDrawIndirect(cb, args.buffer, 0, 2, sizeof(VkDrawIndirectCommand));
    vkCmdDrawIndexedIndirectCount(cb, iargs.buffer, 0, count.buffer, 0, 3, sizeof(VkDrawIndexedIndirectCommand));
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(3, 9, 7, 0), expect(0, 0, 1, 1), expect(1, 0, 3, 0), expect(2, 6, 9, 1)},
                             0, false),
            0);
  destroy(count);
  destroy(iargs);
  destroy(args);
}

INSTANTIATE_TEST_SUITE_P(Promoted, DrawParametersTest, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? "ByExtensionName" : "ByFeature";
                         });

// ---- VK_EXT_extended_dynamic_state

class ExtendedDynamicStateTest : public DrawTest {
 protected:
  VkPhysicalDeviceExtendedDynamicStateFeaturesEXT eds{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTENDED_DYNAMIC_STATE_FEATURES_EXT};
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.deviceExtensions = {VK_EXT_EXTENDED_DYNAMIC_STATE_EXTENSION_NAME};
    eds.extendedDynamicState = VK_TRUE;
    o.featureChain = &eds;
    return o;
  }
};

// A rectangle as a 4-vertex strip in a buffer of 32-byte records (the stride set with vkCmdBindVertexBuffers2EXT),
// drawn with the topology, cull mode and front face set through the EXT commands.
TEST_F(ExtendedDynamicStateTest, TheEXTCommandsSetTheState) {
  auto setCullMode = deviceProc<PFN_vkCmdSetCullModeEXT>("vkCmdSetCullModeEXT");
  auto setFrontFace = deviceProc<PFN_vkCmdSetFrontFaceEXT>("vkCmdSetFrontFaceEXT");
  auto setTopology = deviceProc<PFN_vkCmdSetPrimitiveTopologyEXT>("vkCmdSetPrimitiveTopologyEXT");
  auto bindVertexBuffers2 = deviceProc<PFN_vkCmdBindVertexBuffers2EXT>("vkCmdBindVertexBuffers2EXT");
  ASSERT_TRUE(setCullMode && setFrontFace && setTopology && bindVertexBuffers2);
  VkPhysicalDeviceExtendedDynamicStateFeaturesEXT reported{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTENDED_DYNAMIC_STATE_FEATURES_EXT};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &reported};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(reported.extendedDynamicState);

  PipelineDesc d;
  d.vs = kSpv_draw_color_vert;
  d.vsBytes = sizeof kSpv_draw_color_vert;
  d.fs = kSpv_draw_color_frag;
  d.fsBytes = sizeof kSpv_draw_color_frag;
  d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
  d.dynamic = {VK_DYNAMIC_STATE_CULL_MODE_EXT, VK_DYNAMIC_STATE_FRONT_FACE_EXT, VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY_EXT,
               VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE_EXT};
  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  struct Padded {
    V v;
    float pad[2];
  };
  static_assert(sizeof(Padded) == 32);
  const V a{-0.5f, -0.5f, 1, 0, 0, 1}, b{0.5f, -0.5f, 1, 0, 0, 1}, c{-0.5f, 0.5f, 1, 0, 0, 1},
      e{0.5f, 0.5f, 1, 0, 0, 1};
  const Padded strip[4] = {{a, {}}, {b, {}}, {c, {}}, {e, {}}};
  HostBuffer vb = vertexBuffer(strip, sizeof strip);
  // In framebuffer coordinates (y down) a -> b -> c has a negative signed area ("Basic Polygon Rasterization"): with
  // VK_FRONT_FACE_COUNTER_CLOCKWISE it is back-facing; a strip keeps the winding of its first triangle.
  struct Case {
    VkPrimitiveTopology topology;
    VkCullModeFlags cull;
    VkFrontFace face;
    std::vector<std::array<V, 3>> drawn;
  } cases[] = {
      {VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP,
       VK_CULL_MODE_NONE,
       VK_FRONT_FACE_COUNTER_CLOCKWISE,
       {{a, b, c}, {b, c, e}}},
      {VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP, VK_CULL_MODE_BACK_BIT, VK_FRONT_FACE_COUNTER_CLOCKWISE, {}},
      {VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP, VK_CULL_MODE_BACK_BIT, VK_FRONT_FACE_CLOCKWISE, {{a, b, c}, {b, c, e}}},
      {VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, VK_CULL_MODE_NONE, VK_FRONT_FACE_CLOCKWISE, {{a, b, c}}},
  };
  for (const Case& k : cases) {
    auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
      setTopology(cb, k.topology);
      setCullMode(cb, k.cull);
      setFrontFace(cb, k.face);
      const VkDeviceSize offset = 0, stride = sizeof(Padded);
      bindVertexBuffers2(cb, 0, 1, &vb.buffer, &offset, nullptr, &stride);
      vkCmdDraw(cb, k.topology == VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST ? 3 : 4, 1, 0, 0);
    });
    EXPECT_EQ(compareTriangles(pixels, k.drawn, 0, false), 0)
        << "topology " << k.topology << " cull " << k.cull << " front face " << k.face;
  }
  destroy(vb);
  destroy(color);
  vkDestroyPipeline(device, pipeline, nullptr);
}

// ---- VK_EXT_extended_dynamic_state2

// The parameter: whether extendedDynamicState2LogicOp is enabled (with logicOp; the drawing test runs with it). The
// misuse tests run both ways with the layer off (vkrt's reports).
class ExtendedDynamicState2Test : public DrawTest, public ::testing::WithParamInterface<bool> {
 protected:
  VkPhysicalDeviceExtendedDynamicState2FeaturesEXT eds2{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTENDED_DYNAMIC_STATE_2_FEATURES_EXT};
  virtual bool layered() { return true; }
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.validation = layered();
    o.deviceExtensions = {VK_EXT_EXTENDED_DYNAMIC_STATE_2_EXTENSION_NAME};
    eds2.extendedDynamicState2 = VK_TRUE;
    eds2.extendedDynamicState2LogicOp = GetParam();
    o.features.logicOp = VK_TRUE;
    o.featureChain = &eds2;
    return o;
  }
  // A full-screen triangle of draw_color with the logic op enabled and `dynamic` states.
  PipelineDesc desc(std::vector<VkDynamicState> dynamic) {
    PipelineDesc d;
    d.vs = kSpv_draw_color_vert;
    d.vsBytes = sizeof kSpv_draw_color_vert;
    d.fs = kSpv_draw_color_frag;
    d.fsBytes = sizeof kSpv_draw_color_frag;
    d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
    d.logicOpEnable = VK_TRUE;
    d.logicOp = VK_LOGIC_OP_COPY;  // replaced by vkCmdSetLogicOpEXT's
    d.dynamic = std::move(dynamic);
    return d;
  }
  // The fragment color's bytes: (255, 0, 51, 255).
  static constexpr V kFull[3] = {{-1, -1, 1, 0, 0.2f, 1}, {3, -1, 1, 0, 0.2f, 1}, {-1, 3, 1, 0, 0.2f, 1}};
  static constexpr uint32_t kSource = 0xFF3300FFu;
};

TEST_P(ExtendedDynamicState2Test, TheLogicOpAndTheOtherStatesThroughTheirEXTNames) {
  auto setLogicOp = deviceProc<PFN_vkCmdSetLogicOpEXT>("vkCmdSetLogicOpEXT");
  auto setDiscard = deviceProc<PFN_vkCmdSetRasterizerDiscardEnableEXT>("vkCmdSetRasterizerDiscardEnableEXT");
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkCmdSetPatchControlPointsEXT"), nullptr);
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkCmdSetDepthBiasEnableEXT"), nullptr);
  EXPECT_NE(vkGetDeviceProcAddr(device, "vkCmdSetPrimitiveRestartEnableEXT"), nullptr);
  ASSERT_TRUE(setLogicOp && setDiscard);
  VkPhysicalDeviceExtendedDynamicState2FeaturesEXT reported{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTENDED_DYNAMIC_STATE_2_FEATURES_EXT};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &reported};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(reported.extendedDynamicState2 && reported.extendedDynamicState2LogicOp);
  EXPECT_FALSE(reported.extendedDynamicState2PatchControlPoints) << "no tessellation";

  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(
      createPipeline(desc({VK_DYNAMIC_STATE_LOGIC_OP_EXT, VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE_EXT}), &pipeline),
      VK_SUCCESS);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  HostBuffer vb = vertexBuffer(kFull, sizeof kFull);
  const uint32_t clear = 0x5AC30F96u;
  // "Logical Operations" on the UNORM bytes: s the fragment's, d the attachment's.
  struct Case {
    VkLogicOp op;
    bool discard;
    uint32_t want;
  } cases[] = {{VK_LOGIC_OP_XOR, false, kSource ^ clear},    {VK_LOGIC_OP_AND, false, kSource & clear},
               {VK_LOGIC_OP_COPY_INVERTED, false, ~kSource}, {VK_LOGIC_OP_NO_OP, false, clear},
               {VK_LOGIC_OP_SET, false, 0xFFFFFFFFu},        {VK_LOGIC_OP_SET, true, clear}};
  for (const Case& c : cases) {
    auto pixels = render(
        color, nullptr,
        [&](VkCommandBuffer cb) {
          vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
          setLogicOp(cb, c.op);
          setDiscard(cb, c.discard);
          VkDeviceSize off = 0;
          vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
          vkCmdDraw(cb, 3, 1, 0, 0);
        },
        clear);
    int bad = 0;
    for (uint32_t p : pixels) bad += p != c.want;
    EXPECT_EQ(bad, 0) << "logic op " << c.op << (c.discard ? ", discarded" : "") << ": first pixel 0x" << std::hex
                      << (pixels.empty() ? 0 : pixels[0]) << ", want 0x" << c.want;
  }
  destroy(vb);
  destroy(color);
  vkDestroyPipeline(device, pipeline, nullptr);
}

class ExtendedDynamicState2MisuseTest : public ExtendedDynamicState2Test {
 protected:
  bool layered() override { return false; }
};

TEST_P(ExtendedDynamicState2MisuseTest, TheFeatureRulesAreReported) {
  auto setLogicOp = deviceProc<PFN_vkCmdSetLogicOpEXT>("vkCmdSetLogicOpEXT");
  auto setPatchControlPoints = deviceProc<PFN_vkCmdSetPatchControlPointsEXT>("vkCmdSetPatchControlPointsEXT");
  ASSERT_TRUE(setLogicOp && setPatchControlPoints);
  VkPipeline pipeline = VK_NULL_HANDLE;
  // The patch control points state: its feature is never there.
  EXPECT_NE(createPipeline(desc({VK_DYNAMIC_STATE_PATCH_CONTROL_POINTS_EXT}), &pipeline), VK_SUCCESS);
  expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04870");
  VkCommandBuffer cb = beginOneTime();
  setPatchControlPoints(cb, 3);
  expectVkrtMessage("VUID-vkCmdSetPatchControlPointsEXT-None-04873");
  if (!GetParam()) {
    EXPECT_NE(createPipeline(desc({VK_DYNAMIC_STATE_LOGIC_OP_EXT}), &pipeline), VK_SUCCESS);
    expectVkrtMessage("VUID-VkGraphicsPipelineCreateInfo-pDynamicStates-04869");
    setLogicOp(cb, VK_LOGIC_OP_XOR);
    expectVkrtMessage("VUID-vkCmdSetLogicOpEXT-None-04867");
    vkEndCommandBuffer(cb);
    return;
  }
  setLogicOp(cb, VkLogicOp(VK_LOGIC_OP_SET + 1));
  expectVkrtMessage("VUID-vkCmdSetLogicOpEXT-logicOp-parameter");
  setLogicOp(cb, VK_LOGIC_OP_XOR);
  EXPECT_TRUE(vkrtMessages().empty());
  vkEndCommandBuffer(cb);
  // A draw with the logic op dynamic and never set: reported when it executes, and skipped (the target keeps its
  // clear color).
  ASSERT_EQ(createPipeline(desc({VK_DYNAMIC_STATE_LOGIC_OP_EXT}), &pipeline), VK_SUCCESS);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  HostBuffer vb = vertexBuffer(kFull, sizeof kFull);
  auto pixels = render(
      color, nullptr,
      [&](VkCommandBuffer c) {
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        VkDeviceSize off = 0;
        vkCmdBindVertexBuffers(c, 0, 1, &vb.buffer, &off);
        vkCmdDraw(c, 3, 1, 0, 0);
      },
      0x12345678u);
  expectVkrtMessage("VUID-vkCmdDraw-logicOp-04878");
  ASSERT_FALSE(pixels.empty());
  EXPECT_EQ(pixels[0], 0x12345678u);
  // Set, the same draw runs (XOR with the clear color).
  pixels = render(
      color, nullptr,
      [&](VkCommandBuffer c) {
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        setLogicOp(c, VK_LOGIC_OP_XOR);
        VkDeviceSize off = 0;
        vkCmdBindVertexBuffers(c, 0, 1, &vb.buffer, &off);
        vkCmdDraw(c, 3, 1, 0, 0);
      },
      0x12345678u);
  EXPECT_TRUE(vkrtMessages().empty());
  ASSERT_FALSE(pixels.empty());
  EXPECT_EQ(pixels[0], kSource ^ 0x12345678u);
  destroy(vb);
  destroy(color);
  vkDestroyPipeline(device, pipeline, nullptr);
}

INSTANTIATE_TEST_SUITE_P(Promoted, ExtendedDynamicState2Test, ::testing::Values(true),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? "WithLogicOp" : "WithoutLogicOp";
                         });
INSTANTIATE_TEST_SUITE_P(Promoted, ExtendedDynamicState2MisuseTest, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return p.param ? "WithLogicOp" : "WithoutLogicOp";
                         });

// ---- VK_KHR_maintenance2

class Maintenance2Test : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.deviceExtensions = {VK_KHR_MAINTENANCE_2_EXTENSION_NAME};
    return o;
  }
};

// pointClippingBehavior ALL_CLIP_PLANES: a point is dropped when its vertex is outside the view volume, also where
// its square would cover pixels inside the scissor. The viewport is the target's left half and the scissor the whole
// target: a point at x_f = 15.5 (inside) covers pixel 15; one at x_f = 16.5 (NDC x 1.0625, outside) would cover
// pixel 16 under USER_CLIP_PLANES_ONLY, and covers nothing here.
TEST_F(Maintenance2Test, PointsAreClippedByTheirVertexAgainstTheViewVolume) {
  VkPhysicalDevicePointClippingProperties clip{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_POINT_CLIPPING_PROPERTIES};
  VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES, &clip};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p11};
  vkGetPhysicalDeviceProperties2(physicalDevice, &p2);
  ASSERT_EQ(clip.pointClippingBehavior, VK_POINT_CLIPPING_BEHAVIOR_ALL_CLIP_PLANES);
  EXPECT_EQ(p11.pointClippingBehavior, clip.pointClippingBehavior);

  PipelineDesc d;
  d.vs = kSpv_draw_point_vert;
  d.vsBytes = sizeof kSpv_draw_point_vert;
  d.fs = kSpv_draw_color_frag;
  d.fsBytes = sizeof kSpv_draw_color_frag;
  d.bindings = {{0, 8, VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}};
  d.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  d.viewport = {0, 0, float(kW) / 2, float(kH), 0, 1};
  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  // y: NDC 1/32 is y_f = 16.5, row 16.
  const float points[4] = {0.9375f, 1.0f / 32, 1.0625f, 1.0f / 32};
  HostBuffer vb = vertexBuffer(points, sizeof points);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdDraw(cb, 2, 1, 0, 0);
  });
  ASSERT_EQ(pixels.size(), size_t(kW * kH));
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x)
      EXPECT_EQ(pixels[y * kW + x], x == 15 && y == 16 ? 0xFFFFFFFFu : 0u) << "pixel (" << x << ", " << y << ")";
  destroy(vb);
  destroy(color);
  vkDestroyPipeline(device, pipeline, nullptr);
}

// The structures maintenance2 adds to render passes and image views, and its two depth/stencil layouts, under the
// validation layer: a depth/stencil attachment read as a depth input attachment in a read-only-depth layout, and a
// view whose usage is narrowed to sampling.
TEST_F(Maintenance2Test, InputAttachmentAspectsViewUsageAndTheReadOnlyLayoutsAreTaken) {
  const VkFormat ds = depthStencilFormat();
  VkAttachmentDescription att{};
  att.format = ds;
  att.samples = VK_SAMPLE_COUNT_1_BIT;
  att.loadOp = att.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  att.storeOp = att.stencilStoreOp = VK_ATTACHMENT_STORE_OP_STORE;
  att.initialLayout = att.finalLayout = VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.inputAttachmentCount = 1;
  sub.pInputAttachments = &ref;
  sub.pDepthStencilAttachment = &ref;
  const VkInputAttachmentAspectReference aspect{0, 0, VK_IMAGE_ASPECT_DEPTH_BIT};
  VkRenderPassInputAttachmentAspectCreateInfo aspects{
      VK_STRUCTURE_TYPE_RENDER_PASS_INPUT_ATTACHMENT_ASPECT_CREATE_INFO};
  aspects.aspectReferenceCount = 1;
  aspects.pAspectReferences = &aspect;
  VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO, &aspects};
  rp.attachmentCount = 1;
  rp.pAttachments = &att;
  rp.subpassCount = 1;
  rp.pSubpasses = &sub;
  VkRenderPass pass = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateRenderPass(device, &rp, nullptr, &pass), VK_SUCCESS);
  vkDestroyRenderPass(device, pass, nullptr);

  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = kColorFormat;
  ci.extent = {4, 4, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  VkImage image = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &image), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, 0);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &mai, nullptr, &memory), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(device, image, memory, 0), VK_SUCCESS);
  VkImageViewUsageCreateInfo usage{VK_STRUCTURE_TYPE_IMAGE_VIEW_USAGE_CREATE_INFO};
  usage.usage = VK_IMAGE_USAGE_SAMPLED_BIT;
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO, &usage};
  vi.image = image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = kColorFormat;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  EXPECT_EQ(vkCreateImageView(device, &vi, nullptr, &view), VK_SUCCESS);
  vkDestroyImageView(device, view, nullptr);
  vkDestroyImage(device, image, nullptr);
  vkFreeMemory(device, memory, nullptr);
}

}  // namespace
}  // namespace vkrt::test
