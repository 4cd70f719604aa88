// The draw's state resolution (gfx::resolveState): each dynamic state comes from the command buffer's values, every
// other one from the pipeline; and the VkDynamicState -> bit mapping of every supported state.
#include <gtest/gtest.h>

#include "gfx/draw_state.hpp"
#include "gfx/graphics_pipeline.hpp"

namespace vkrt::gfx {
namespace {

// A pipeline state and a dynamic state that differ in every field resolveState may take.
void makeStates(GraphicsPipelineDesc* p, DrawExecState* d) {
  raster::State& s = p->state;
  s.topology = raster::Topology::TriangleList;
  s.viewportCount = 1;
  s.viewports[0] = {0, 0, 10, 10, 0, 1};
  s.scissors[0] = {0, 0, 10, 10};
  s.lineWidth = 1;
  s.depthBiasConstant = 1, s.depthBiasClamp = 2, s.depthBiasSlope = 3;
  s.blendConstants[0] = 0.25f;
  s.minDepthBounds = 0.1f, s.maxDepthBounds = 0.9f;
  s.front.compareMask = 1, s.back.compareMask = 2;
  s.front.writeMask = 3, s.back.writeMask = 4;
  s.front.reference = 5, s.back.reference = 6;
  s.cullMode = raster::CullBack;
  s.frontFace = raster::FrontFace::CounterClockwise;
  s.depthTest = false, s.depthWrite = false, s.depthCompare = raster::CompareOp::Less;
  s.depthBoundsTest = false, s.stencilTest = false;
  s.front.failOp = raster::StencilOp::Keep, s.back.passOp = raster::StencilOp::Keep;
  s.front.compareOp = raster::CompareOp::Always;
  s.rasterizerDiscard = false, s.depthBiasEnable = false, s.primitiveRestart = false;
  s.logicOp = raster::LogicOp::Copy;

  raster::State& y = d->dynamic;
  y.topology = raster::Topology::TriangleStrip;
  y.viewportCount = 1;
  y.viewports[0] = {1, 2, 30, 40, 0.5f, 0.75f};
  y.scissors[0] = {3, 4, 5, 6};
  y.lineWidth = 2;
  y.depthBiasConstant = 7, y.depthBiasClamp = 8, y.depthBiasSlope = 9;
  y.blendConstants[0] = 0.5f;
  y.minDepthBounds = 0.2f, y.maxDepthBounds = 0.3f;
  y.front.compareMask = 11, y.back.compareMask = 12;
  y.front.writeMask = 13, y.back.writeMask = 14;
  y.front.reference = 15, y.back.reference = 16;
  y.cullMode = raster::CullFront;
  y.frontFace = raster::FrontFace::Clockwise;
  y.depthTest = true, y.depthWrite = true, y.depthCompare = raster::CompareOp::Greater;
  y.depthBoundsTest = true, y.stencilTest = true;
  y.front.failOp = raster::StencilOp::Zero, y.back.passOp = raster::StencilOp::Invert;
  y.front.compareOp = raster::CompareOp::Equal;
  y.rasterizerDiscard = true, y.depthBiasEnable = true, y.primitiveRestart = true;
  y.logicOp = raster::LogicOp::Xor;
}

// Whether field group `bit` of `r` holds the dynamic values (true) or the pipeline's (false); -1 when mixed.
int takenFromDynamic(uint32_t bit, const raster::State& r) {
  auto pick = [](bool dyn, bool stat) { return dyn ? 1 : stat ? 0 : -1; };
  switch (bit) {
    case kDynViewport:
    case kDynViewportWithCount:
      return pick(r.viewports[0].x == 1 && r.viewports[0].maxDepth == 0.75f, r.viewports[0].width == 10);
    case kDynScissor:
    case kDynScissorWithCount:
      return pick(r.scissors[0].x == 3 && r.scissors[0].height == 6, r.scissors[0].width == 10);
    case kDynLineWidth: return pick(r.lineWidth == 2, r.lineWidth == 1);
    case kDynDepthBias:
      return pick(r.depthBiasConstant == 7 && r.depthBiasClamp == 8 && r.depthBiasSlope == 9,
                  r.depthBiasConstant == 1 && r.depthBiasSlope == 3);
    case kDynBlendConstants: return pick(r.blendConstants[0] == 0.5f, r.blendConstants[0] == 0.25f);
    case kDynDepthBounds:
      return pick(r.minDepthBounds == 0.2f && r.maxDepthBounds == 0.3f,
                  r.minDepthBounds == 0.1f && r.maxDepthBounds == 0.9f);
    case kDynStencilCompareMask:
      return pick(r.front.compareMask == 11 && r.back.compareMask == 12,
                  r.front.compareMask == 1 && r.back.compareMask == 2);
    case kDynStencilWriteMask:
      return pick(r.front.writeMask == 13 && r.back.writeMask == 14, r.front.writeMask == 3 && r.back.writeMask == 4);
    case kDynStencilReference:
      return pick(r.front.reference == 15 && r.back.reference == 16, r.front.reference == 5 && r.back.reference == 6);
    case kDynCullMode: return pick(r.cullMode == raster::CullFront, r.cullMode == raster::CullBack);
    case kDynFrontFace:
      return pick(r.frontFace == raster::FrontFace::Clockwise, r.frontFace == raster::FrontFace::CounterClockwise);
    case kDynTopology:
      return pick(r.topology == raster::Topology::TriangleStrip, r.topology == raster::Topology::TriangleList);
    case kDynDepthTestEnable: return pick(r.depthTest, !r.depthTest);
    case kDynDepthWriteEnable: return pick(r.depthWrite, !r.depthWrite);
    case kDynDepthCompareOp:
      return pick(r.depthCompare == raster::CompareOp::Greater, r.depthCompare == raster::CompareOp::Less);
    case kDynDepthBoundsTestEnable: return pick(r.depthBoundsTest, !r.depthBoundsTest);
    case kDynStencilTestEnable: return pick(r.stencilTest, !r.stencilTest);
    case kDynStencilOp:
      return pick(r.front.failOp == raster::StencilOp::Zero && r.back.passOp == raster::StencilOp::Invert &&
                      r.front.compareOp == raster::CompareOp::Equal,
                  r.front.failOp == raster::StencilOp::Keep && r.back.passOp == raster::StencilOp::Keep &&
                      r.front.compareOp == raster::CompareOp::Always);
    case kDynRasterizerDiscardEnable: return pick(r.rasterizerDiscard, !r.rasterizerDiscard);
    case kDynDepthBiasEnable: return pick(r.depthBiasEnable, !r.depthBiasEnable);
    case kDynPrimitiveRestartEnable: return pick(r.primitiveRestart, !r.primitiveRestart);
    case kDynLogicOp: return pick(r.logicOp == raster::LogicOp::Xor, r.logicOp == raster::LogicOp::Copy);
    default: return -1;
  }
}

TEST(GfxVertexStateResolution, EachDynamicStateComesFromTheCommandBuffer) {
  for (uint32_t bit = 0; bit < kDynCount; ++bit) {
    if (bit == kDynVertexStride) continue;  // strides are resolved per binding by the draw (draw_executor.cpp)
    GraphicsPipelineDesc p;
    DrawExecState d;
    makeStates(&p, &d);
    p.dynamicMask = 1u << bit;
    raster::State r;
    resolveState(p, d, &r);
    for (uint32_t other = 0; other < kDynCount; ++other) {
      if (other == kDynVertexStride) continue;
      const bool sameGroup = other == bit || (bit == kDynViewport && other == kDynViewportWithCount) ||
                             (bit == kDynViewportWithCount && other == kDynViewport) ||
                             (bit == kDynScissor && other == kDynScissorWithCount) ||
                             (bit == kDynScissorWithCount && other == kDynScissor);
      EXPECT_EQ(takenFromDynamic(other, r), sameGroup ? 1 : 0)
          << "dynamic " << dynamicStateName(bit) << ", checking " << dynamicStateName(other);
    }
  }
}

TEST(GfxVertexStateResolution, ViewportCountComesWithTheCount) {
  GraphicsPipelineDesc p;
  DrawExecState d;
  makeStates(&p, &d);
  p.state.viewportCount = 1;
  d.dynamic.viewportCount = 1;
  d.dynamic.viewports[0].width = 77;
  p.dynamicMask = 1u << kDynViewportWithCount;
  raster::State r;
  resolveState(p, d, &r);
  EXPECT_EQ(r.viewportCount, 1u);
  EXPECT_EQ(r.viewports[0].width, 77.0f);
}

TEST(GfxVertexStateResolution, DynamicStateBits) {
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_VIEWPORT), int(kDynViewport));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_STENCIL_REFERENCE), int(kDynStencilReference));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_CULL_MODE), int(kDynCullMode));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_FRONT_FACE), int(kDynFrontFace));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY), int(kDynTopology));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT), int(kDynViewportWithCount));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT), int(kDynScissorWithCount));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE), int(kDynVertexStride));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE), int(kDynDepthTestEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE), int(kDynDepthWriteEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_DEPTH_COMPARE_OP), int(kDynDepthCompareOp));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE), int(kDynDepthBoundsTestEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE), int(kDynStencilTestEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_STENCIL_OP), int(kDynStencilOp));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE), int(kDynRasterizerDiscardEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE), int(kDynDepthBiasEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE), int(kDynPrimitiveRestartEnable));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_LOGIC_OP_EXT), int(kDynLogicOp));
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_PATCH_CONTROL_POINTS_EXT), -1);
  EXPECT_EQ(dynamicBit(VK_DYNAMIC_STATE_VERTEX_INPUT_EXT), -1);
  EXPECT_STREQ(dynamicStateName(kDynStencilOp), "VK_DYNAMIC_STATE_STENCIL_OP");
  EXPECT_STREQ(dynamicStateName(kDynLogicOp), "VK_DYNAMIC_STATE_LOGIC_OP_EXT");
}

}  // namespace
}  // namespace vkrt::gfx
