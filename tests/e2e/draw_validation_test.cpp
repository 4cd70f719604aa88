// The draw commands' rules, both sides: the misuse is reported with its VUID (when recorded, or for the rules on the
// bound pipeline when the draw executes) and the draw has no effect; the corrected commands draw without a report.
// The validation layer is off (it would report the same misuse).
#include "e2e/draw_fixture.hpp"

#include "draw_color.frag.spv.h"
#include "draw_color.vert.spv.h"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

class DrawValidationTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.validation = false;
    return o;
  }
  void SetUp() override {
    DrawTest::SetUp();
    if (HasFatalFailure()) return;
    color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT);
    const V quad[6] = {{-1, -1, 1, 1, 1, 1}, {1, -1, 1, 1, 1, 1}, {1, 1, 1, 1, 1, 1},
                       {-1, -1, 1, 1, 1, 1}, {1, 1, 1, 1, 1, 1},  {-1, 1, 1, 1, 1, 1}};
    vb = vertexBuffer(quad, sizeof quad);
    const uint16_t idx[6] = {0, 1, 2, 3, 4, 5};
    ib = vertexBuffer(idx, sizeof idx, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    const VkDrawIndirectCommand cmds[2] = {{6, 1, 0, 0}, {6, 1, 0, 0}};
    args = vertexBuffer(cmds, sizeof cmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    plain = vertexBuffer(cmds, sizeof cmds, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  }
  void TearDown() override {
    if (device) {
      for (VkPipeline p : pipelines) vkDestroyPipeline(device, p, nullptr);
      for (HostBuffer* b : {&vb, &ib, &args, &plain}) destroy(*b);
      destroy(color);
    }
    DrawTest::TearDown();
  }
  VkPipeline pipeline(std::vector<VkDynamicState> dynamic = {}, uint32_t colors = 1) {
    PipelineDesc d;
    d.vs = kSpv_draw_color_vert;
    d.vsBytes = sizeof kSpv_draw_color_vert;
    d.fs = kSpv_draw_color_frag;
    d.fsBytes = sizeof kSpv_draw_color_frag;
    d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
    d.dynamic = std::move(dynamic);
    d.colorCount = d.blendCount = colors;
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(createPipeline(d, &p), VK_SUCCESS);
    pipelines.push_back(p);
    return p;
  }
  void bindVertices(VkCommandBuffer cb) {
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
  }
  // The number of white pixels (a full-screen white quad drawn: all; skipped: none).
  static int white(const std::vector<uint32_t>& px) {
    int n = 0;
    for (uint32_t p : px) n += p == 0xFFFFFFFFu;
    return n;
  }

  Target color;
  HostBuffer vb, ib, args, plain;
  std::vector<VkPipeline> pipelines;
};

TEST_F(DrawValidationTest, NoGraphicsPipelineBound) {
  auto px = render(color, nullptr, [&](VkCommandBuffer cb) {
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDraw-None-02700");
  EXPECT_EQ(white(px), 0);
  VkPipeline p = pipeline();
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(white(px), int(kW * kH));
}

TEST_F(DrawValidationTest, OutsideRenderPass) {
  VkPipeline p = pipeline();
  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
  bindVertices(cb);
  vkCmdDraw(cb, 6, 1, 0, 0);
  expectVkrtMessage("VUID-vkCmdDraw-renderpass");
  vkCmdBindIndexBuffer(cb, ib.buffer, 0, VK_INDEX_TYPE_UINT16);
  vkCmdDrawIndexed(cb, 6, 1, 0, 0, 0);
  expectVkrtMessage("VUID-vkCmdDrawIndexed-renderpass");
  vkCmdDrawIndirect(cb, args.buffer, 0, 1, 16);
  expectVkrtMessage("VUID-vkCmdDrawIndirect-renderpass");
  submitAndWait(cb);
  EXPECT_TRUE(vkrtMessages().empty());
}

TEST_F(DrawValidationTest, DynamicStateNotSet) {
  VkPipeline p = pipeline({VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY});
  const VkViewport vp{0, 0, float(kW), float(kH), 0, 1};
  auto px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdSetPrimitiveTopology(cb, VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDraw-commandBuffer-02701");
  EXPECT_EQ(white(px), 0);
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdSetViewport(cb, 0, 1, &vp);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDraw-primitiveTopology-03420");
  EXPECT_EQ(white(px), 0);
  // Binding a pipeline with the viewport static makes the viewport set before undefined for the next dynamic one.
  VkPipeline fixed = pipeline();
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetPrimitiveTopology(cb, VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);  // draws
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, fixed);
    vkCmdDraw(cb, 6, 1, 0, 0);  // draws
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdDraw(cb, 6, 1, 0, 0);  // viewport and topology undefined again
  });
  expectVkrtMessage("VUID-vkCmdDraw-commandBuffer-02701");
  EXPECT_EQ(white(px), int(kW * kH));
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetPrimitiveTopology(cb, VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(white(px), int(kW * kH));
}

TEST_F(DrawValidationTest, VertexAndIndexBuffersBound) {
  VkPipeline p = pipeline();
  auto px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDraw-None-04007");
  EXPECT_EQ(white(px), 0);
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bindVertices(cb);
    vkCmdDrawIndexed(cb, 6, 1, 0, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDrawIndexed-None-07312");
  EXPECT_EQ(white(px), 0);
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bindVertices(cb);
    vkCmdBindIndexBuffer(cb, ib.buffer, 0, VK_INDEX_TYPE_UINT16);
    vkCmdDrawIndexed(cb, 6, 1, 0, 0, 0);
  });
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(white(px), int(kW * kH));
}

TEST_F(DrawValidationTest, BindingCommands) {
  VkCommandBuffer cb = beginOneTime();
  VkDeviceSize off = 0;
  vkCmdBindVertexBuffers(cb, 0, 1, &args.buffer, &off);  // INDIRECT usage only
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers-pBuffers-00627");
  off = sizeof(VkDrawIndirectCommand) * 2;
  vkCmdBindVertexBuffers(cb, 0, 1, &plain.buffer, &off);
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers-pOffsets-00626");
  vkCmdBindVertexBuffers(cb, 31, 2, &plain.buffer, &off);
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers-firstBinding-00625");
  off = 0;
  const VkDeviceSize size = 64, stride = 4096;
  vkCmdBindVertexBuffers2(cb, 0, 1, &plain.buffer, &off, &size, nullptr);
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers2-pSizes-03358");
  vkCmdBindVertexBuffers2(cb, 0, 1, &plain.buffer, &off, nullptr, &stride);
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers2-pStrides-03362");
  vkCmdBindIndexBuffer(cb, ib.buffer, 1, VK_INDEX_TYPE_UINT16);
  expectVkrtMessage("VUID-vkCmdBindIndexBuffer-offset-00432");
  vkCmdBindIndexBuffer(cb, vb.buffer, 0, VK_INDEX_TYPE_UINT16);
  expectVkrtMessage("VUID-vkCmdBindIndexBuffer-buffer-00433");
  vkCmdBindIndexBuffer(cb, ib.buffer, 0, VK_INDEX_TYPE_UINT8_EXT);
  expectVkrtMessage("VUID-vkCmdBindIndexBuffer-indexType-02765");
  // The valid forms.
  vkCmdBindVertexBuffers(cb, 0, 1, &plain.buffer, &off);
  const VkDeviceSize okSize = 16, okStride = 16;
  vkCmdBindVertexBuffers2(cb, 0, 1, &plain.buffer, &off, &okSize, &okStride);
  vkCmdBindIndexBuffer(cb, ib.buffer, 2, VK_INDEX_TYPE_UINT16);
  submitAndWait(cb);
  EXPECT_TRUE(vkrtMessages().empty());
}

TEST_F(DrawValidationTest, IndirectBuffersOffsetsAndStrides) {
  VkPipeline p = pipeline();
  auto px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bindVertices(cb);
    vkCmdDrawIndirect(cb, plain.buffer, 0, 1, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirect-buffer-02709");
    vkCmdDrawIndirect(cb, args.buffer, 2, 1, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirect-offset-02710");
    vkCmdDrawIndirect(cb, args.buffer, 0, 2, 8);
    expectVkrtMessage("VUID-vkCmdDrawIndirect-drawCount-00476");
    vkCmdDrawIndirect(cb, args.buffer, 0, 3, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirect-drawCount-00488");
    vkCmdDrawIndirect(cb, args.buffer, 20, 1, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirect-drawCount-00487");
    vkCmdDrawIndirectCount(cb, args.buffer, 0, args.buffer, 2, 2, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirectCount-countBufferOffset-02716");
    vkCmdDrawIndirectCount(cb, args.buffer, 0, plain.buffer, 0, 2, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirectCount-countBuffer-02715");
    vkCmdDrawIndirectCount(cb, args.buffer, 0, args.buffer, 0, 2, 12);
    expectVkrtMessage("VUID-vkCmdDrawIndirectCount-stride-03110");
    vkCmdDrawIndirectCount(cb, args.buffer, 0, args.buffer, 0, 3, 16);
    expectVkrtMessage("VUID-vkCmdDrawIndirectCount-maxDrawCount-03111");
  });
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(white(px), 0);  // nothing was recorded
  px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bindVertices(cb);
    vkCmdDrawIndirect(cb, args.buffer, 0, 2, 16);
    vkCmdDrawIndirectCount(cb, args.buffer, 0, args.buffer, 0, 2, 16);  // count = 6 (the first word), max 2
  });
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(white(px), int(kW * kH));
}

TEST_F(DrawValidationTest, PipelineColorCountMatchesRendering) {
  VkPipeline two = pipeline({}, 2);
  auto px = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, two);
    bindVertices(cb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  expectVkrtMessage("VUID-vkCmdDraw-colorAttachmentCount-06179");
  EXPECT_EQ(white(px), 0);
}

TEST_F(DrawValidationTest, DynamicStateSetters) {
  VkCommandBuffer cb = beginOneTime();
  vkCmdSetLineWidth(cb, 2.0f);
  expectVkrtMessage("VUID-vkCmdSetLineWidth-lineWidth-00788");
  const VkViewport vp{0, 0, 4, 4, 0, 1};
  vkCmdSetViewport(cb, 1, 1, &vp);
  expectVkrtMessage("VUID-vkCmdSetViewport-firstViewport-01224");
  const VkRect2D negative{{-1, 0}, {4, 4}};
  vkCmdSetScissor(cb, 0, 1, &negative);
  expectVkrtMessage("VUID-vkCmdSetScissor-x-00595");
  vkCmdSetScissorWithCount(cb, 1, &negative);
  expectVkrtMessage("VUID-vkCmdSetScissorWithCount-x-03399");
  const VkViewport two[2] = {vp, vp};
  vkCmdSetViewportWithCount(cb, 2, two);
  expectVkrtMessage("VUID-vkCmdSetViewportWithCount-viewportCount-03394");
  vkCmdSetDepthBounds(cb, -0.5f, 1.0f);
  expectVkrtMessage("VUID-vkCmdSetDepthBounds-minDepthBounds-00600");
  vkCmdSetDepthBias(cb, 1.0f, 0.5f, 1.0f);  // depthBiasClamp is not enabled by this fixture
  expectVkrtMessage("VUID-vkCmdSetDepthBias-depthBiasClamp-00790");
  vkCmdSetStencilReference(cb, 0, 1);
  expectVkrtMessage("VUID-vkCmdSetStencilReference-faceMask-requiredbitmask");
  // The valid forms.
  const VkRect2D ok{{0, 0}, {4, 4}};
  vkCmdSetLineWidth(cb, 1.0f);
  vkCmdSetViewport(cb, 0, 1, &vp);
  vkCmdSetScissor(cb, 0, 1, &ok);
  vkCmdSetScissorWithCount(cb, 1, &ok);
  vkCmdSetViewportWithCount(cb, 1, &vp);
  vkCmdSetDepthBounds(cb, 0.0f, 1.0f);
  vkCmdSetDepthBias(cb, 1.0f, 0.0f, 1.0f);
  vkCmdSetStencilReference(cb, VK_STENCIL_FACE_FRONT_BIT, 1);
  submitAndWait(cb);
  EXPECT_TRUE(vkrtMessages().empty());
}

}  // namespace
}  // namespace vkrt::test
