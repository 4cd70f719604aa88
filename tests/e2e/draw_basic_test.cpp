// Draws whose pixels are computed independently (draw_fixture.hpp's reference rasterization): a triangle with
// interpolated vertex colors, indexed draws (16- and 32-bit indices, vertexOffset, firstIndex), instanced draws with
// per-instance attributes, and the indirect and indirect count draws.
#include <algorithm>
#include <array>

#include "e2e/draw_fixture.hpp"

#include "draw_builtins.vert.spv.h"
#include "draw_color.frag.spv.h"
#include "draw_color.vert.spv.h"
#include "draw_depth_initializer.frag.spvasm.spv.h"
#include "draw_instanced.vert.spv.h"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

class DrawBasicTest : public DrawTest {
 protected:
  // A pipeline of draw_color.vert/.frag with {vec2 pos, vec4 color} vertices at binding 0.
  PipelineDesc colorPipeline() {
    PipelineDesc d;
    d.vs = kSpv_draw_color_vert;
    d.vsBytes = sizeof kSpv_draw_color_vert;
    d.fs = kSpv_draw_color_frag;
    d.fsBytes = sizeof kSpv_draw_color_frag;
    d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
    return d;
  }
  // colorPipeline() with a depth/stencil attachment, the depth test `compare` and depth writes `write`.
  PipelineDesc depthPipeline(VkCompareOp compare, bool write) {
    PipelineDesc d = colorPipeline();
    d.withDepthStencil = true;
    d.depthStencil.depthTestEnable = VK_TRUE;
    d.depthStencil.depthWriteEnable = write;
    d.depthStencil.depthCompareOp = compare;
    return d;
  }
  // A depth/stencil target of depthStencilFormat().
  Target depthTarget() {
    return createTarget(depthStencilFormat(), VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                        VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT);
  }
  // The triangle of TriangleWithInterpolatedColors drawn into `color` (cleared to `clear`) with colorPipeline():
  // its pixels, after checking them against the reference.
  static constexpr V kTri[3] = {{-0.8f, -0.9f, 1, 0, 0, 1}, {0.9f, -0.3f, 0, 1, 0, 1}, {-0.2f, 0.85f, 0, 0, 1, 1}};
  std::vector<uint32_t> renderTriangle(const Target& color, uint32_t clear) {
    VkPipeline pipeline;
    EXPECT_EQ(createPipeline(colorPipeline(), &pipeline), VK_SUCCESS);
    HostBuffer vb = vertexBuffer(kTri, sizeof kTri);
    auto pixels = render(
        color, nullptr,
        [&](VkCommandBuffer cb) {
          vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
          VkDeviceSize off = 0;
          vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
          vkCmdDraw(cb, 3, 1, 0, 0);
        },
        clear);
    EXPECT_EQ(compareTriangles(pixels, {{kTri[0], kTri[1], kTri[2]}}, clear), 0);
    destroy(vb);
    vkDestroyPipeline(device, pipeline, nullptr);
    return pixels;
  }
};

TEST_F(DrawBasicTest, TriangleWithInterpolatedColors) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  renderTriangle(color, 0xFF202020u);
  // Some pixels are covered and some are not (the reference is not trivially all background).
  int covered = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) covered += coverage(kTri[0], kTri[1], kTri[2], px, py) == 1;
  EXPECT_GT(covered, 200);
  EXPECT_LT(covered, int(kW * kH) - 200);
  destroy(color);
}

// A view of a mutable-format image renders, clears and is read in the view's format ("Image Views"): an R32_UINT
// image seen through an R8G8B8A8_UNORM view holds the view's RGBA8 texels. Before, the render target took the image's
// format: the clear and every fragment were encoded as R32_UINT (CTS image.mutable.*_draw_*, 1,200 cases).
TEST_F(DrawBasicTest, AViewOfAnotherFormatRendersAndClearsInTheViewsFormat) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  // The same target again, on an R32_UINT image created with VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT.
  vkDestroyImageView(device, color.view, nullptr);
  vkDestroyImage(device, color.image, nullptr);
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.flags = VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = VK_FORMAT_R32_UINT;
  ci.extent = {kW, kH, 1};
  ci.mipLevels = ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  ASSERT_EQ(vkCreateImage(device, &ci, nullptr, &color.image), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(device, color.image, color.memory, 0), VK_SUCCESS);
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = color.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = kColorFormat;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  ASSERT_EQ(vkCreateImageView(device, &vi, nullptr, &color.view), VK_SUCCESS);
  const std::vector<uint32_t> pixels = renderTriangle(color, 0xFF402010u);
  EXPECT_EQ(pixels[0], 0xFF402010u);  // a corner no triangle covers: the clear, as RGBA8 bytes
  destroy(color);
}

TEST_F(DrawBasicTest, IndexedUint16AndUint32WithOffsets) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(colorPipeline(), &pipeline), VK_SUCCESS);
  // Vertices 0..3: a quad on the left (red); 4..7: a quad on the right (green). Two unused vertices first, so
  // that vertexOffset 2 is needed.
  const V verts[10] = {{0, 0, 0, 0, 0, 0},         {0, 0, 0, 0, 0, 0},        {-0.9f, -0.9f, 1, 0, 0, 1},
                       {-0.1f, -0.9f, 1, 0, 0, 1}, {-0.1f, 0.9f, 1, 0, 0, 1}, {-0.9f, 0.9f, 1, 0, 0, 1},
                       {0.1f, -0.5f, 0, 1, 0, 1},  {0.9f, -0.5f, 0, 1, 0, 1}, {0.9f, 0.5f, 0, 1, 0, 1},
                       {0.1f, 0.5f, 0, 1, 0, 1}};
  HostBuffer vb = vertexBuffer(verts, sizeof verts);
  const uint16_t idx16[] = {7, 7, 0, 1, 2, 0, 2, 3};  // firstIndex 2
  const uint32_t idx32[] = {4, 5, 6, 4, 6, 7};
  HostBuffer ib16 = vertexBuffer(idx16, sizeof idx16, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  HostBuffer ib32 = vertexBuffer(idx32, sizeof idx32, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdBindIndexBuffer(cb, ib16.buffer, 0, VK_INDEX_TYPE_UINT16);
    vkCmdDrawIndexed(cb, 6, 1, 2, 2, 0);
    vkCmdBindIndexBuffer(cb, ib32.buffer, 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(cb, 6, 1, 0, 2, 0);
  });
  const V* q = verts + 2;
  EXPECT_EQ(compareTriangles(pixels, {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}, {q[4], q[5], q[6]}, {q[4], q[6], q[7]}},
                             0, false),
            0);
  EXPECT_EQ(pixels[16 * kW + 4], 0xFF0000FFu);   // red quad
  EXPECT_EQ(pixels[16 * kW + 27], 0xFF00FF00u);  // green quad
  EXPECT_EQ(pixels[2 * kW + 27], 0u);            // above the green quad
  destroy(ib32);
  destroy(ib16);
  destroy(vb);
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
}

TEST_F(DrawBasicTest, InstancedWithPerInstanceAttributes) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  PipelineDesc d;
  d.vs = kSpv_draw_instanced_vert;
  d.vsBytes = sizeof kSpv_draw_instanced_vert;
  d.fs = kSpv_draw_color_frag;
  d.fsBytes = sizeof kSpv_draw_color_frag;
  d.bindings = {{0, 8, VK_VERTEX_INPUT_RATE_VERTEX}, {1, 12, VK_VERTEX_INPUT_RATE_INSTANCE}};
  // Per instance: vec2 offset (float) and an RGBA8 UNORM color at byte 8.
  d.attributes = {
      {0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {2, 1, VK_FORMAT_R32G32_SFLOAT, 0}, {3, 1, VK_FORMAT_R8G8B8A8_UNORM, 8}};
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  const float tri[6] = {-0.3f, -0.3f, 0.3f, -0.3f, 0.0f, 0.3f};
  struct Inst {
    float dx, dy;
    uint8_t rgba[4];
  };
  // Instance 0 is skipped by firstInstance = 1.
  const Inst inst[4] = {{0, 0, {255, 255, 255, 255}},
                        {-0.6f, -0.6f, {255, 0, 0, 255}},
                        {0.6f, -0.6f, {0, 255, 0, 255}},
                        {0.0f, 0.6f, {0, 0, 255, 255}}};
  HostBuffer vb = vertexBuffer(tri, sizeof tri);
  HostBuffer ib = vertexBuffer(inst, sizeof inst);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkBuffer bufs[2] = {vb.buffer, ib.buffer};
    VkDeviceSize offs[2] = {0, 0};
    vkCmdBindVertexBuffers(cb, 0, 2, bufs, offs);
    vkCmdDraw(cb, 3, 3, 0, 1);
  });
  std::vector<std::array<V, 3>> tris;
  for (int i = 1; i < 4; ++i) {
    const float r = inst[i].rgba[0] / 255.0f, g = inst[i].rgba[1] / 255.0f, b = inst[i].rgba[2] / 255.0f;
    std::array<V, 3> t;
    for (int k = 0; k < 3; ++k) t[k] = {tri[2 * k] + inst[i].dx, tri[2 * k + 1] + inst[i].dy, r, g, b, 1};
    tris.push_back(t);
  }
  EXPECT_EQ(compareTriangles(pixels, tris, 0, false), 0);
  EXPECT_EQ(pixels[(kH / 2) * kW + kW / 2], 0u);  // instance 0 (centre, white) was not drawn
  destroy(ib);
  destroy(vb);
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
}

// Indirect draws: each record draws one small triangle at its own place (firstVertex or firstIndex selects it); the
// shader writes InstanceIndex and the provoking vertex's VertexIndex into the color, so the pixels tell which record
// and instance drew them.
class DrawIndirectTest : public QuadrantDrawTest {
 protected:
  void SetUp() override {
    DrawTest::SetUp();
    if (HasFatalFailure()) return;
    setUpQuadrants(kSpv_draw_builtins_vert, sizeof kSpv_draw_builtins_vert);
  }
  // The expected flat color of quadrant q drawn with InstanceIndex `instance` (the last instance drawn wins:
  // instances are drawn in order); its provoking vertex is vertex 3q.
  std::array<V, 3> expect(int q, uint32_t instance) {
    std::array<V, 3> t = quads[q];
    for (V& x : t) {
      x.r = instance / 255.0f;
      x.g = 3 * q / 255.0f;
      x.b = 0;
    }
    return t;
  }
};

TEST_F(DrawIndirectTest, DrawIndirectMultiDraw) {
  // Record k draws quadrant k's triangle (firstVertex 3k), instanceCount 2, firstInstance 5 + k; quadrant 3 not drawn.
  const VkDrawIndirectCommand cmds[3] = {{3, 2, 0, 5}, {3, 2, 3, 6}, {3, 2, 6, 7}};
  HostBuffer args = vertexBuffer(cmds, sizeof cmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDrawIndirect(cb, args.buffer, 0, 3, sizeof(VkDrawIndirectCommand));
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(0, 6), expect(1, 7), expect(2, 8)}, 0, false), 0);
  destroy(args);
}

TEST_F(DrawIndirectTest, DrawIndexedIndirectWithStride) {
  // Records 32 bytes apart; record k draws quadrant 3 - k through indices 3(3-k).., one instance, firstInstance k.
  struct Rec {
    VkDrawIndexedIndirectCommand c;
    uint32_t pad[3];
  };
  Rec recs[2] = {{{3, 1, 9, 0, 0}, {}}, {{3, 1, 6, 0, 1}, {}}};
  HostBuffer args = vertexBuffer(recs, sizeof recs, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDrawIndexedIndirect(cb, args.buffer, 0, 2, sizeof(Rec));
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(3, 0), expect(2, 1)}, 0, false), 0);
  destroy(args);
}

TEST_F(DrawIndirectTest, IndirectCountTakesTheSmallerOfCountAndMax) {
  const VkDrawIndirectCommand cmds[4] = {{3, 1, 0, 0}, {3, 1, 3, 0}, {3, 1, 6, 0}, {3, 1, 9, 0}};
  const VkDrawIndexedIndirectCommand icmds[4] = {{3, 1, 0, 0, 0}, {3, 1, 3, 0, 0}, {3, 1, 6, 0, 0}, {3, 1, 9, 0, 0}};
  HostBuffer args = vertexBuffer(cmds, sizeof cmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  HostBuffer iargs = vertexBuffer(icmds, sizeof icmds, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  const uint32_t counts[2] = {2, 9};  // count 2 (< max 4); count 9 (> max 3)
  HostBuffer count = vertexBuffer(counts, sizeof counts, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDrawIndirectCount(cb, args.buffer, 0, count.buffer, 0, 4, sizeof(VkDrawIndirectCommand));
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(0, 0), expect(1, 0)}, 0, false), 0);
  pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    bind(cb);
    vkCmdDrawIndexedIndirectCount(cb, iargs.buffer, 0, count.buffer, 4, 3, sizeof(VkDrawIndexedIndirectCommand));
  });
  EXPECT_EQ(compareTriangles(pixels, {expect(0, 0), expect(1, 0), expect(2, 0)}, 0, false), 0);
  destroy(count);
  destroy(iargs);
  destroy(args);
}

// An output built-in's OpVariable initializer is its value until the shader stores one: a fragment shader whose
// FragDepth is initialized to 0.25 and never stored writes depth 0.25. Then a full-screen draw at depth 0 with LESS
// passes everywhere. Before, the initializer was ignored (the fragment kept its depth 0, the second draw failed the
// test: CTS renderpass.depth_stencil_write_conditions.depth_*_initialize_*).
TEST_F(DrawBasicTest, FragDepthInitializerIsTheFragmentsDepth) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  Target depth = depthTarget();
  PipelineDesc d = depthPipeline(VK_COMPARE_OP_ALWAYS, true);
  d.fs = kSpv_draw_depth_initializer_frag_spvasm;
  d.fsBytes = sizeof kSpv_draw_depth_initializer_frag_spvasm;
  VkPipeline first, second;
  ASSERT_EQ(createPipeline(d, &first), VK_SUCCESS);
  ASSERT_EQ(createPipeline(depthPipeline(VK_COMPARE_OP_LESS, false), &second), VK_SUCCESS);
  const V verts[6] = {{-1, -1, 0, 1, 0, 1}, {1, -1, 0, 1, 0, 1}, {1, 1, 0, 1, 0, 1},
                      {-1, -1, 0, 1, 0, 1}, {1, 1, 0, 1, 0, 1},  {-1, 1, 0, 1, 0, 1}};
  HostBuffer vb = vertexBuffer(verts, sizeof verts);
  auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, first);
    vkCmdDraw(cb, 6, 1, 0, 0);  // red, depth 0.25 from the initializer
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, second);
    vkCmdDraw(cb, 6, 1, 0, 0);  // green at depth 0: 0 < 0.25 everywhere
  });
  int wrong = 0;
  for (uint32_t p : pixels) wrong += p != 0xFF00FF00u;
  EXPECT_EQ(wrong, 0) << "pixel 0: " << std::hex << pixels[0];
  destroy(vb);
  vkDestroyPipeline(device, first, nullptr);
  vkDestroyPipeline(device, second, nullptr);
  destroy(depth);
  destroy(color);
}

// Occlusion queries (vkCmdBeginQuery / vkCmdEndQuery, core 1.0): the samples that pass the depth test between begin
// and end. Quads whose edges lie on pixel boundaries (no sample on an edge): A covers pixels [8, 24) x [8, 24) (256
// samples), B the left half [0, 16) x [0, 32) (512). Before, vkCmdBeginQuery and vkCmdEndQuery resolved to NULL and
// occlusion pools were refused (CTS fragment_operations.occlusion_query.*, dynamic_rendering.*.random.*).
class DrawOcclusionTest : public DrawBasicTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawBasicTest::options();
    o.features12.hostQueryReset = VK_TRUE;
    o.features.occlusionQueryPrecise = VK_TRUE;
    return o;
  }
};

TEST_F(DrawOcclusionTest, QueriesCountTheSamplesThatPassTheDepthTest) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  Target depth = depthTarget();
  VkPipeline less, lessEqual;
  ASSERT_EQ(createPipeline(depthPipeline(VK_COMPARE_OP_LESS, true), &less), VK_SUCCESS);
  ASSERT_EQ(createPipeline(depthPipeline(VK_COMPARE_OP_LESS_OR_EQUAL, true), &lessEqual), VK_SUCCESS);
  auto quad = [](float x0, float y0, float x1, float y1) {
    return std::array<V, 6>{V{x0, y0, 1, 1, 1, 1}, V{x1, y0, 1, 1, 1, 1}, V{x1, y1, 1, 1, 1, 1},
                            V{x0, y0, 1, 1, 1, 1}, V{x1, y1, 1, 1, 1, 1}, V{x0, y1, 1, 1, 1, 1}};
  };
  std::array<V, 12> verts;
  const auto a = quad(-0.5f, -0.5f, 0.5f, 0.5f), b = quad(-1.0f, -1.0f, 0.0f, 1.0f);
  std::copy(a.begin(), a.end(), verts.begin());
  std::copy(b.begin(), b.end(), verts.begin() + 6);
  HostBuffer vb = vertexBuffer(verts.data(), sizeof verts);
  VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qi.queryType = VK_QUERY_TYPE_OCCLUSION;
  qi.queryCount = 4;
  VkQueryPool pool;
  ASSERT_EQ(vkCreateQueryPool(device, &qi, nullptr, &pool), VK_SUCCESS);
  vkResetQueryPool(device, pool, 0, 4);
  render(color, &depth, [&](VkCommandBuffer cb) {
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, less);
    vkCmdBeginQuery(cb, pool, 0, 0);
    vkCmdDraw(cb, 6, 1, 0, 0);  // A over depth 1: all 256 pass
    vkCmdEndQuery(cb, pool, 0);
    vkCmdBeginQuery(cb, pool, 1, 0);
    vkCmdDraw(cb, 6, 1, 0, 0);  // A again, LESS against its own depth: none
    vkCmdEndQuery(cb, pool, 1);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, lessEqual);
    vkCmdBeginQuery(cb, pool, 2, VK_QUERY_CONTROL_PRECISE_BIT);  // (the count is exact either way)
    vkCmdDraw(cb, 6, 1, 6, 0);  // B, LESS_OR_EQUAL: all 512 (equal over A, less elsewhere)
    vkCmdDraw(cb, 6, 1, 0, 0);  // and A once more: 256
    vkCmdEndQuery(cb, pool, 2);
    vkCmdBeginQuery(cb, pool, 3, 0);  // no draw
    vkCmdEndQuery(cb, pool, 3);
  });
  uint64_t r[8] = {};
  ASSERT_EQ(vkGetQueryPoolResults(device, pool, 0, 4, sizeof r, r, 16,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT),
            VK_SUCCESS);
  const uint64_t want[4] = {256, 0, 768, 0};
  for (int q = 0; q < 4; ++q) {
    EXPECT_EQ(r[2 * q], want[q]) << "query " << q;
    EXPECT_EQ(r[2 * q + 1], 1u) << "query " << q << " availability";
  }
  vkDestroyQueryPool(device, pool, nullptr);
  destroy(vb);
  vkDestroyPipeline(device, less, nullptr);
  vkDestroyPipeline(device, lessEqual, nullptr);
  destroy(depth);
  destroy(color);
}

}  // namespace
}  // namespace vkrt::test
