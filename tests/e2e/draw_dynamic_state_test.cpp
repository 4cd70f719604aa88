// Every dynamic state of Vulkan 1.3 (and the 1.0 ones the tests can observe) changing what a draw renders. Scenes are
// axis-aligned rectangles whose edges fall on pixel boundaries (coordinates in 1/16 steps of NDC on a 32x32 target),
// so the expected image is exact; or triangles checked with the fixture's reference.
#include "e2e/draw_fixture.hpp"

#include "draw_color.frag.spv.h"
#include "draw_depth.vert.spv.h"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

struct DVertex {
  float x, y, z;
  float r, g, b, a;
};

struct Rect {
  float x0, y0, x1, y1, z;
  uint32_t rgba;
};

float channel(uint32_t rgba, int c) { return float((rgba >> (8 * c)) & 0xFF) / 255.0f; }

class DrawDynamicStateTest : public DrawTest {
 protected:
  void SetUp() override {
    DrawTest::SetUp();
    if (HasFatalFailure()) return;
    color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT);
    depth = createTarget(depthStencilFormat(), VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                         VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT);
  }
  void TearDown() override {
    if (device) {
      for (auto& b : buffers) destroy(b);
      for (VkPipeline p : pipelines) vkDestroyPipeline(device, p, nullptr);
      destroy(color);
      destroy(depth);
    }
    DrawTest::TearDown();
  }

  PipelineDesc desc(std::vector<VkDynamicState> dynamic) {
    PipelineDesc d;
    d.vs = kSpv_draw_depth_vert;
    d.vsBytes = sizeof kSpv_draw_depth_vert;
    d.fs = kSpv_draw_color_frag;
    d.fsBytes = sizeof kSpv_draw_color_frag;
    d.bindings = {{0, sizeof(DVertex), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 12}};
    d.withDepthStencil = true;
    d.depthStencil.depthCompareOp = VK_COMPARE_OP_LESS;
    d.depthStencil.minDepthBounds = 0;
    d.depthStencil.maxDepthBounds = 1;
    d.dynamic = std::move(dynamic);
    return d;
  }
  VkPipeline make(const PipelineDesc& d) {
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(createPipeline(d, &p), VK_SUCCESS);
    pipelines.push_back(p);
    return p;
  }
  // Two triangles per rectangle, vertices in a new buffer; returns the buffer.
  VkBuffer rects(const std::vector<Rect>& rs) {
    std::vector<DVertex> v;
    for (const Rect& r : rs) {
      const float c[4] = {channel(r.rgba, 0), channel(r.rgba, 1), channel(r.rgba, 2), channel(r.rgba, 3)};
      for (auto [x, y] : {std::pair{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}})
        v.push_back({x, y, r.z, c[0], c[1], c[2], c[3]});
    }
    buffers.push_back(vertexBuffer(v.data(), v.size() * sizeof(DVertex)));
    return buffers.back().buffer;
  }
  void bindVertices(VkCommandBuffer cb, VkBuffer b) {
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &b, &off);
  }
  // The expected image: rectangles painted in order (no tests), mapped through a viewport (x, y, w, h) and clipped
  // to a scissor.
  static std::vector<uint32_t> paint(const std::vector<Rect>& rs, float vx = 0, float vy = 0, float vw = kW,
                                     float vh = kH, VkRect2D scissor = {{0, 0}, {kW, kH}}) {
    std::vector<uint32_t> img(kW * kH, 0);
    for (const Rect& r : rs) {
      const double X0 = (r.x0 + 1) * vw / 2 + vx, X1 = (r.x1 + 1) * vw / 2 + vx;
      const double Y0 = (r.y0 + 1) * vh / 2 + vy, Y1 = (r.y1 + 1) * vh / 2 + vy;
      for (int py = 0; py < int(kH); ++py)
        for (int px = 0; px < int(kW); ++px) {
          const double cx = px + 0.5, cy = py + 0.5;
          const bool inScissor = px >= scissor.offset.x && px < scissor.offset.x + int(scissor.extent.width) &&
                                 py >= scissor.offset.y && py < scissor.offset.y + int(scissor.extent.height);
          if (cx > X0 && cx < X1 && cy > Y0 && cy < Y1 && inScissor) img[py * kW + px] = r.rgba;
        }
    }
    return img;
  }
  static int mismatches(const std::vector<uint32_t>& got, const std::vector<uint32_t>& want) {
    int bad = 0;
    for (size_t i = 0; i < got.size(); ++i)
      if (!near(got[i], want[i]) && ++bad <= 5)
        ADD_FAILURE() << "pixel (" << i % kW << ", " << i / kW << "): got 0x" << std::hex << got[i] << ", want 0x"
                      << want[i];
    return bad;
  }

  Target color, depth;
  std::vector<VkPipeline> pipelines;
  std::vector<HostBuffer> buffers;
};

constexpr uint32_t kRed = 0xFF0000FFu, kGreen = 0xFF00FF00u, kBlue = 0xFFFF0000u;

TEST_F(DrawDynamicStateTest, CullModeAndFrontFace) {
  VkPipeline p = make(desc({VK_DYNAMIC_STATE_CULL_MODE, VK_DYNAMIC_STATE_FRONT_FACE}));
  // One rectangle = two triangles of the same winding. In framebuffer coordinates (y down) the vertex order
  // (x0,y0) -> (x1,y0) -> (x1,y1) has the signed area a = -1/2 sum(x_i y_i+1 - x_i+1 y_i) < 0 ("Basic Polygon
  // Rasterization"), so with VK_FRONT_FACE_COUNTER_CLOCKWISE it is back-facing.
  const Rect r{-0.5f, -0.5f, 0.5f, 0.5f, 0.5f, kRed};
  const double fx[3] = {8, 24, 24}, fy[3] = {8, 8, 24};
  double a = 0;
  for (int i = 0; i < 3; ++i) a += fx[i] * fy[(i + 1) % 3] - fx[(i + 1) % 3] * fy[i];
  a *= -0.5;
  ASSERT_LT(a, 0);
  const bool frontIfCcw = a > 0;
  VkBuffer vb = rects({r});
  struct Case {
    VkCullModeFlags cull;
    VkFrontFace face;
    bool drawn;
  } cases[] = {{VK_CULL_MODE_BACK_BIT, VK_FRONT_FACE_COUNTER_CLOCKWISE, frontIfCcw},
               {VK_CULL_MODE_BACK_BIT, VK_FRONT_FACE_CLOCKWISE, !frontIfCcw},
               {VK_CULL_MODE_FRONT_BIT, VK_FRONT_FACE_COUNTER_CLOCKWISE, !frontIfCcw},
               {VK_CULL_MODE_NONE, VK_FRONT_FACE_CLOCKWISE, true},
               {VK_CULL_MODE_FRONT_AND_BACK, VK_FRONT_FACE_CLOCKWISE, false}};
  for (const Case& c : cases) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetCullMode(cb, c.cull);
      vkCmdSetFrontFace(cb, c.face);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    EXPECT_EQ(mismatches(pixels, paint(c.drawn ? std::vector<Rect>{r} : std::vector<Rect>{})), 0)
        << "cull " << c.cull << " front face " << c.face;
  }
}

TEST_F(DrawDynamicStateTest, PrimitiveTopology) {
  VkPipeline p = make(desc({VK_DYNAMIC_STATE_PRIMITIVE_TOPOLOGY}));
  // Four corners of a rectangle in strip order: a list draws the first triangle only, a strip the whole rectangle.
  const DVertex v[4] = {{-0.5f, -0.5f, 0.5f, 0, 0, 1, 1},
                        {0.5f, -0.5f, 0.5f, 0, 0, 1, 1},
                        {-0.5f, 0.5f, 0.5f, 0, 0, 1, 1},
                        {0.5f, 0.5f, 0.5f, 0, 0, 1, 1}};
  buffers.push_back(vertexBuffer(v, sizeof v));
  VkBuffer vb = buffers.back().buffer;
  for (VkPrimitiveTopology t : {VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST, VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetPrimitiveTopology(cb, t);
      bindVertices(cb, vb);
      vkCmdDraw(cb, t == VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST ? 3 : 4, 1, 0, 0);
    });
    const V a{-0.5f, -0.5f, 0, 0, 1, 1}, b{0.5f, -0.5f, 0, 0, 1, 1}, c{-0.5f, 0.5f, 0, 0, 1, 1},
        d{0.5f, 0.5f, 0, 0, 1, 1};
    std::vector<std::array<V, 3>> tris = {{a, b, c}};
    if (t == VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP) tris.push_back({b, c, d});
    EXPECT_EQ(compareTriangles(pixels, tris, 0, false), 0) << "topology " << t;
  }
}

TEST_F(DrawDynamicStateTest, PrimitiveRestartEnable) {
  PipelineDesc d = desc({VK_DYNAMIC_STATE_PRIMITIVE_RESTART_ENABLE});
  d.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_STRIP;
  VkPipeline p = make(d);
  // 65536 vertices, so that the restart index 0xFFFF is also a real vertex when restart is off.
  std::vector<DVertex> v(65536, DVertex{0, 0, 0.5f, 1, 1, 1, 1});
  const float corners[8][2] = {{-0.875f, -0.875f}, {-0.125f, -0.875f}, {-0.875f, -0.125f}, {-0.125f, -0.125f},
                               {0.125f, 0.125f},   {0.875f, 0.125f},   {0.125f, 0.875f},   {0.875f, 0.875f}};
  for (int i = 0; i < 8; ++i) v[i] = {corners[i][0], corners[i][1], 0.5f, 1, 1, 1, 1};
  v[0xFFFF] = {0.875f, -0.875f, 0.5f, 1, 1, 1, 1};
  buffers.push_back(vertexBuffer(v.data(), v.size() * sizeof(DVertex)));
  VkBuffer vb = buffers.back().buffer;
  const uint16_t idx[9] = {0, 1, 2, 3, 0xFFFF, 4, 5, 6, 7};
  buffers.push_back(vertexBuffer(idx, sizeof idx, VK_BUFFER_USAGE_INDEX_BUFFER_BIT));
  VkBuffer ib = buffers.back().buffer;
  for (VkBool32 restart : {VK_TRUE, VK_FALSE}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetPrimitiveRestartEnable(cb, restart);
      bindVertices(cb, vb);
      vkCmdBindIndexBuffer(cb, ib, 0, VK_INDEX_TYPE_UINT16);
      vkCmdDrawIndexed(cb, 9, 1, 0, 0, 0);
    });
    // The strip's triangles ("Triangle Strips"): every three consecutive indices, a restart index starting a new strip.
    std::vector<std::array<V, 3>> tris;
    std::vector<uint32_t> strip;
    auto flush = [&] {
      for (size_t i = 2; i < strip.size(); ++i) {
        std::array<V, 3> t;
        for (int k = 0; k < 3; ++k) {
          const DVertex& x = v[strip[i - 2 + k]];
          t[k] = {x.x, x.y, 1, 1, 1, 1};
        }
        tris.push_back(t);
      }
      strip.clear();
    };
    for (uint16_t i : idx) {
      if (restart && i == 0xFFFF)
        flush();
      else
        strip.push_back(i);
    }
    flush();
    EXPECT_EQ(compareTriangles(pixels, tris, 0, false), 0) << "restart " << restart;
  }
}

TEST_F(DrawDynamicStateTest, ViewportAndScissorWithCount) {
  VkPipeline p = make(desc({VK_DYNAMIC_STATE_VIEWPORT_WITH_COUNT, VK_DYNAMIC_STATE_SCISSOR_WITH_COUNT}));
  const Rect r{-0.5f, -0.5f, 0.5f, 0.5f, 0.5f, kGreen};
  VkBuffer vb = rects({r});
  const VkViewport vps[2] = {{0, 0, 32, 32, 0, 1}, {16, 0, 16, 32, 0, 1}};
  const VkRect2D scs[2] = {{{0, 0}, {32, 32}}, {{0, 0}, {32, 12}}};
  for (int k = 0; k < 2; ++k) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetViewportWithCount(cb, 1, &vps[k]);
      vkCmdSetScissorWithCount(cb, 1, &scs[k]);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    EXPECT_EQ(mismatches(pixels, paint({r}, vps[k].x, vps[k].y, vps[k].width, vps[k].height, scs[k])), 0) << k;
  }
}

TEST_F(DrawDynamicStateTest, ViewportScissorAndBlendConstants) {
  PipelineDesc d = desc({VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR, VK_DYNAMIC_STATE_BLEND_CONSTANTS});
  // Color = src * CONSTANT_COLOR: the blend constants scale the rectangle's white.
  d.blend = {VK_TRUE,
             VK_BLEND_FACTOR_CONSTANT_COLOR,
             VK_BLEND_FACTOR_ZERO,
             VK_BLEND_OP_ADD,
             VK_BLEND_FACTOR_CONSTANT_ALPHA,
             VK_BLEND_FACTOR_ZERO,
             VK_BLEND_OP_ADD,
             0xF};
  VkPipeline p = make(d);
  const Rect r{-0.5f, -0.5f, 0.5f, 0.5f, 0.5f, 0xFFFFFFFFu};
  VkBuffer vb = rects({r});
  const VkViewport vp{0, 16, 16, 16, 0, 1};
  const VkRect2D sc{{4, 0}, {28, 32}};
  const float constants[4] = {1.0f, 0.0f, 0.4f, 0.6f};
  auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetScissor(cb, 0, 1, &sc);
    vkCmdSetBlendConstants(cb, constants);
    bindVertices(cb, vb);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  const Rect scaled{r.x0, r.y0, r.x1, r.y1, r.z, rgba8(1.0, 0.0, 0.4, 0.6)};
  EXPECT_EQ(mismatches(pixels, paint({scaled}, vp.x, vp.y, vp.width, vp.height, sc)), 0);
}

TEST_F(DrawDynamicStateTest, DepthTestWriteAndCompareOp) {
  VkPipeline p = make(desc(
      {VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE, VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE, VK_DYNAMIC_STATE_DEPTH_COMPARE_OP}));
  const Rect nearRect{-0.75f, -0.75f, 0.25f, 0.25f, 0.25f, kRed}, farRect{-0.25f, -0.25f, 0.75f, 0.75f, 0.75f, kGreen};
  VkBuffer vb = rects({nearRect, farRect});
  struct Case {
    VkBool32 test, write;
    VkCompareOp op;
    std::vector<Rect> expect;  // painted in order
  } cases[] = {
      {VK_FALSE, VK_TRUE, VK_COMPARE_OP_LESS, {nearRect, farRect}},  // no test: draw order
      {VK_TRUE, VK_TRUE, VK_COMPARE_OP_LESS, {farRect, nearRect}},   // the nearer wins
      {VK_TRUE, VK_FALSE, VK_COMPARE_OP_LESS, {nearRect, farRect}},  // nothing written: both pass vs 1.0
      {VK_TRUE, VK_TRUE, VK_COMPARE_OP_GREATER, {}},                 // nothing is farther than 1.0
      {VK_TRUE, VK_TRUE, VK_COMPARE_OP_ALWAYS, {nearRect, farRect}},
  };
  for (const Case& c : cases) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetDepthTestEnable(cb, c.test);
      vkCmdSetDepthWriteEnable(cb, c.write);
      vkCmdSetDepthCompareOp(cb, c.op);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 12, 1, 0, 0);
    });
    EXPECT_EQ(mismatches(pixels, paint(c.expect)), 0) << "test " << c.test << " write " << c.write << " op " << c.op;
  }
}

TEST_F(DrawDynamicStateTest, DepthBoundsTestEnableAndBounds) {
  PipelineDesc d = desc({VK_DYNAMIC_STATE_DEPTH_BOUNDS_TEST_ENABLE, VK_DYNAMIC_STATE_DEPTH_BOUNDS});
  d.depthStencil.depthTestEnable = VK_TRUE;
  d.depthStencil.depthWriteEnable = VK_TRUE;
  VkPipeline p = make(d);
  // The first rectangle writes depth 0.25 (LESS against the cleared 1.0); the second, nearer still and over everything,
  // passes the depth bounds test only where the stored depth lies in the bounds ("Depth Bounds Test").
  const Rect first{-0.75f, -0.75f, 0.0f, 0.0f, 0.25f, kRed}, second{-1, -1, 1, 1, 0.1f, kBlue};
  VkBuffer vb = rects({first, second});
  for (VkBool32 enable : {VK_FALSE, VK_TRUE}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetDepthBoundsTestEnable(cb, VK_FALSE);
      vkCmdSetDepthBounds(cb, 0.0f, 1.0f);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
      vkCmdSetDepthBoundsTestEnable(cb, enable);
      vkCmdSetDepthBounds(cb, 0.0f, 0.5f);
      vkCmdDraw(cb, 6, 1, 6, 0);
    });
    // Without the test the blue rectangle covers everything; with it only where depth 0.25 was stored.
    std::vector<uint32_t> want = paint({second});
    if (enable) want = paint({Rect{first.x0, first.y0, first.x1, first.y1, 0, kBlue}});
    EXPECT_EQ(mismatches(pixels, want), 0) << "depth bounds test " << enable;
  }
}

TEST_F(DrawDynamicStateTest, StencilTestEnableOpAndReference) {
  PipelineDesc d =
      desc({VK_DYNAMIC_STATE_STENCIL_TEST_ENABLE, VK_DYNAMIC_STATE_STENCIL_OP, VK_DYNAMIC_STATE_STENCIL_REFERENCE,
            VK_DYNAMIC_STATE_STENCIL_COMPARE_MASK, VK_DYNAMIC_STATE_STENCIL_WRITE_MASK});
  VkPipeline p = make(d);
  const Rect mask{-0.5f, -0.5f, 0.5f, 0.0f, 0.5f, kRed}, full{-1, -1, 1, 1, 0.4f, kGreen};
  VkBuffer vb = rects({mask, full});
  for (VkBool32 test : {VK_FALSE, VK_TRUE}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetStencilCompareMask(cb, VK_STENCIL_FACE_FRONT_AND_BACK, 0xFF);
      vkCmdSetStencilWriteMask(cb, VK_STENCIL_FACE_FRONT_AND_BACK, 0xFF);
      // Pass 1: write 5 into the stencil where the red rectangle is.
      vkCmdSetStencilTestEnable(cb, VK_TRUE);
      vkCmdSetStencilOp(cb, VK_STENCIL_FACE_FRONT_AND_BACK, VK_STENCIL_OP_KEEP, VK_STENCIL_OP_REPLACE,
                        VK_STENCIL_OP_KEEP, VK_COMPARE_OP_ALWAYS);
      vkCmdSetStencilReference(cb, VK_STENCIL_FACE_FRONT_AND_BACK, 5);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
      // Pass 2: green everywhere the stencil equals 5 (or everywhere without the test).
      vkCmdSetStencilTestEnable(cb, test);
      vkCmdSetStencilOp(cb, VK_STENCIL_FACE_FRONT_AND_BACK, VK_STENCIL_OP_KEEP, VK_STENCIL_OP_KEEP, VK_STENCIL_OP_KEEP,
                        VK_COMPARE_OP_EQUAL);
      vkCmdDraw(cb, 6, 1, 6, 0);
    });
    const Rect greenMask{mask.x0, mask.y0, mask.x1, mask.y1, 0, kGreen};
    EXPECT_EQ(mismatches(pixels, test ? paint({greenMask}) : paint({full})), 0) << "stencil test " << test;
  }
}

TEST_F(DrawDynamicStateTest, RasterizerDiscardEnable) {
  VkPipeline p = make(desc({VK_DYNAMIC_STATE_RASTERIZER_DISCARD_ENABLE}));
  const Rect r{-0.5f, -0.5f, 0.5f, 0.5f, 0.5f, kBlue};
  VkBuffer vb = rects({r});
  for (VkBool32 discard : {VK_TRUE, VK_FALSE}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetRasterizerDiscardEnable(cb, discard);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    EXPECT_EQ(mismatches(pixels, paint(discard ? std::vector<Rect>{} : std::vector<Rect>{r})), 0) << discard;
  }
}

TEST_F(DrawDynamicStateTest, DepthBiasEnableAndDepthBias) {
  PipelineDesc d =
      desc({VK_DYNAMIC_STATE_DEPTH_BIAS_ENABLE, VK_DYNAMIC_STATE_DEPTH_BIAS, VK_DYNAMIC_STATE_DEPTH_TEST_ENABLE,
            VK_DYNAMIC_STATE_DEPTH_WRITE_ENABLE, VK_DYNAMIC_STATE_DEPTH_COMPARE_OP});
  VkPipeline p = make(d);
  // Two rectangles at the same depth 0.5; the second passes LESS only when a negative bias moves it nearer ("Depth
  // Bias": o = m * slopeFactor + r * constantFactor, r at most 2^-23 relative to 0.5 for any depth format: 1000 r is
  // far larger than rounding and far smaller than 0.5).
  const Rect a{-0.75f, -0.75f, 0.25f, 0.25f, 0.5f, kRed}, b{-0.25f, -0.25f, 0.75f, 0.75f, 0.5f, kGreen};
  VkBuffer vb = rects({a, b});
  for (VkBool32 bias : {VK_FALSE, VK_TRUE}) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      vkCmdSetDepthTestEnable(cb, VK_TRUE);
      vkCmdSetDepthWriteEnable(cb, VK_TRUE);
      vkCmdSetDepthCompareOp(cb, VK_COMPARE_OP_LESS);
      vkCmdSetDepthBias(cb, -1000.0f, 0.0f, 0.0f);
      vkCmdSetDepthBiasEnable(cb, VK_FALSE);
      bindVertices(cb, vb);
      vkCmdDraw(cb, 6, 1, 0, 0);
      vkCmdSetDepthBiasEnable(cb, bias);
      vkCmdDraw(cb, 6, 1, 6, 0);
    });
    EXPECT_EQ(mismatches(pixels, bias ? paint({a, b}) : paint({b, a})), 0) << "bias " << bias;
  }
}

TEST_F(DrawDynamicStateTest, VertexInputBindingStride) {
  VkPipeline p = make(desc({VK_DYNAMIC_STATE_VERTEX_INPUT_BINDING_STRIDE}));
  // Six red vertices (a left rectangle) interleaved with six green ones (a right rectangle): with stride 56 the draw
  // reads the red ones; from offset 28 with stride 56 the green ones; with stride 28 from 0 the first six of the
  // interleaved sequence (a mix), checked as triangles.
  const Rect left{-0.875f, -0.5f, -0.125f, 0.5f, 0.5f, kRed}, right{0.125f, -0.5f, 0.875f, 0.5f, 0.5f, kGreen};
  std::vector<DVertex> v;
  auto corners = [](const Rect& r, uint32_t rgba) {
    std::vector<DVertex> out;
    for (auto [x, y] : {std::pair{r.x0, r.y0}, {r.x1, r.y0}, {r.x1, r.y1}, {r.x0, r.y0}, {r.x1, r.y1}, {r.x0, r.y1}})
      out.push_back({x, y, r.z, channel(rgba, 0), channel(rgba, 1), channel(rgba, 2), channel(rgba, 3)});
    return out;
  };
  const auto l = corners(left, kRed), r = corners(right, kGreen);
  for (int i = 0; i < 6; ++i) {
    v.push_back(l[i]);
    v.push_back(r[i]);
  }
  buffers.push_back(vertexBuffer(v.data(), v.size() * sizeof(DVertex)));
  VkBuffer vb = buffers.back().buffer;
  for (int k = 0; k < 2; ++k) {
    auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
      const VkDeviceSize offset = k ? sizeof(DVertex) : 0, stride = 2 * sizeof(DVertex);
      vkCmdBindVertexBuffers2(cb, 0, 1, &vb, &offset, nullptr, &stride);
      vkCmdDraw(cb, 6, 1, 0, 0);
    });
    EXPECT_EQ(mismatches(pixels, paint({k ? right : left})), 0) << k;
  }
  auto pixels = render(color, &depth, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    const VkDeviceSize offset = 0, stride = sizeof(DVertex);
    vkCmdBindVertexBuffers2(cb, 0, 1, &vb, &offset, nullptr, &stride);
    vkCmdDraw(cb, 6, 1, 0, 0);
  });
  std::vector<std::array<V, 3>> tris;
  for (int t = 0; t < 2; ++t) {
    std::array<V, 3> tri;
    for (int k = 0; k < 3; ++k) {
      const DVertex& x = v[3 * t + k];
      tri[k] = {x.x, x.y, x.r, x.g, x.b, x.a};
    }
    tris.push_back(tri);
  }
  EXPECT_EQ(compareTriangles(pixels, tris, 0, true), 0);
}

}  // namespace
}  // namespace vkrt::test
