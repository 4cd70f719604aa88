// Fragment quads drawn on both of vkrt's paths (VKRT_SPMD unset: the SPMD quad where the compiler supports the
// shader; VKRT_SPMD=0: four fibers): derivatives, discard, demotion and helperInvocationEXT() in the pixels, against
// values computed here from the pixel coordinates.
#include <cstdlib>
#include <string>

#include "draw_derivatives.frag.spv.h"
#include "draw_fragcoord_w.frag.spv.h"
#include "draw_fragcoord_w.vert.spv.h"
#include "draw_point.vert.spv.h"
#include "draw_point_builtins.frag.spv.h"
#include "draw_sparse_locations.frag.spv.h"
#include "draw_sparse_locations.vert.spv.h"
#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

// `spmd` false: the device is created with VKRT_SPMD=0 (read at device creation); the variable is put back after.
class DrawQuadShadingTest : public DrawTest, public ::testing::WithParamInterface<bool> {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.features13.shaderDemoteToHelperInvocation = VK_TRUE;
    return o;
  }
  void SetUp() override {
    const char* was = std::getenv("VKRT_SPMD");
    had_ = was != nullptr;
    if (had_) was_ = was;
    setenv("VKRT_SPMD", GetParam() ? "1" : "0", 1);
    DrawTest::SetUp();
  }
  void TearDown() override {
    DrawTest::TearDown();
    // The setting is process-wide and read at the next device creation: back to what the run asked for.
    setenv("VKRT_SPMD", had_ ? was_.c_str() : "1", 1);
  }
  bool had_ = false;
  std::string was_;
};

TEST_P(DrawQuadShadingTest, DerivativesDiscardAndDemotionInThePixels) {
  // One triangle over the whole target (every quad fully covered), alpha 0.5.
  const float color[4] = {0, 0, 0, 0.5f};
  const uint32_t clear = 0xFF202020u;
  auto pixels = drawFullScreen(kSpv_draw_derivatives_frag, sizeof kSpv_draw_derivatives_frag, color, clear);
  ASSERT_EQ(pixels.size(), size_t(kW) * kH);
  // Pixel (px, py), centre (px + 0.5, py + 0.5), in the quad whose top-left pixel is (qx, qy) = (px & ~1, py & ~1):
  // dFdxFine(x^2) = (qx + 1.5)^2 - (qx + 0.5)^2 = 2 qx + 2 (the same in both rows), dFdyCoarse(y^2) = 2 qy + 2,
  // fwidthFine(x y) = |d(x y)/dx| + |d(x y)/dy| = (py + 0.5) + (px + 0.5).
  int mismatches = 0, discarded = 0, demoted = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) {
      const int qx = px & ~1, qy = py & ~1;
      uint32_t want = rgba8((2.0 * qx + 2) / 64, (2.0 * qy + 2) / 64, (px + py + 1.0) / 64, 0.5);
      if ((px + 2 * py) % 5 == 0) {
        want = clear, ++discarded;
      } else if ((3 * px + py) % 7 == 0) {
        want = clear, ++demoted;  // a demoted fragment writes nothing
      }
      const uint32_t got = pixels[size_t(py) * kW + px];
      if (!near(got, want) && ++mismatches <= 5)
        ADD_FAILURE() << "pixel (" << px << ", " << py << "): " << std::hex << got << " want " << want;
    }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(discarded, 100);
  EXPECT_GT(demoted, 100);
}

// Inputs at locations that are not the slots in order (1.z, 2, 5; location 3 written by the vertex stage and not
// read): the executor places each slot at its location (on the SPMD path a word of the quad's four lanes at a time).
// The expected colour at each pixel centre from the NDC position: 0.5 (color + (0.25 ndc + 0.5, 0.25, 1)).
TEST_P(DrawQuadShadingTest, InputsAtSparseLocationsReachTheirVariables) {
  const float r = 0.2f, g = 0.4f, b = 0.6f, a = 0.5f;
  const float rgba[4] = {r, g, b, a};
  const std::vector<uint32_t> pixels =
      drawFullScreen(kSpv_draw_sparse_locations_frag, sizeof kSpv_draw_sparse_locations_frag, rgba, 0,
                     kSpv_draw_sparse_locations_vert, sizeof kSpv_draw_sparse_locations_vert);
  ASSERT_EQ(pixels.size(), size_t(kW) * kH);
  int mismatches = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) {
      const double nx = (px + 0.5) / kW * 2 - 1, ny = (py + 0.5) / kH * 2 - 1;
      const uint32_t want =
          rgba8(0.5 * (r + 0.25 * nx + 0.5), 0.5 * (g + 0.25 * ny + 0.5), 0.5 * (b + 0.25), 0.5 * (a + 1.0));
      const uint32_t got = pixels[size_t(py) * kW + px];
      if (!near(got, want) && ++mismatches <= 5)
        ADD_FAILURE() << "pixel (" << px << ", " << py << "): " << std::hex << got << " want " << want;
    }
  EXPECT_EQ(mismatches, 0);
}

// A shader that reads FragCoord and whose one input is the same at every vertex: the rasterizer writes that input
// once per triangle and computes FragCoord's w (1 / w_c, linear in screen space) for this shader's quads all the
// same (tile.cpp interpolateQuad). The full-screen triangle's vertices (-1, -1), (3, -1), (-1, 3) have w_c 1, 3, 1:
// at NDC x, 1 / w_c = 1 - t + t / 3 with t = (x + 1) / 4; z is 0.25 everywhere.
TEST_P(DrawQuadShadingTest, FragCoordWWhereNothingVaries) {
  const float rgba[4] = {0.1f, 0.2f, 0.3f, 0.8f};
  const std::vector<uint32_t> pixels =
      drawFullScreen(kSpv_draw_fragcoord_w_frag, sizeof kSpv_draw_fragcoord_w_frag, rgba, 0, kSpv_draw_fragcoord_w_vert,
                     sizeof kSpv_draw_fragcoord_w_vert);
  ASSERT_EQ(pixels.size(), size_t(kW) * kH);
  int mismatches = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) {
      const double nx = (px + 0.5) / kW * 2 - 1, t = (nx + 1) / 4;
      const uint32_t want = rgba8(1 - t + t / 3, 0.25, 0.3, 0.8);
      const uint32_t got = pixels[size_t(py) * kW + px];
      if (!near(got, want) && ++mismatches <= 5)
        ADD_FAILURE() << "pixel (" << px << ", " << py << "): " << std::hex << got << " want " << want;
    }
  EXPECT_EQ(mismatches, 0);
}

// The per-lane built-ins the executor hands a shader that declares them (gfx/draw_executor.cpp sets them only then):
// points (size 1: largePoints is not advertised) whose fragment reads PointCoord, (0.5, 0.5) at the one pixel, and
// SampleMask, 1 on a one-sample target.
TEST_P(DrawQuadShadingTest, PointCoordAndSampleMaskIn) {
  PipelineDesc d;
  d.vs = kSpv_draw_point_vert;
  d.vsBytes = sizeof kSpv_draw_point_vert;
  d.fs = kSpv_draw_point_builtins_frag;
  d.fsBytes = sizeof kSpv_draw_point_builtins_frag;
  d.bindings = {{0, 8, VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}};
  d.topology = VK_PRIMITIVE_TOPOLOGY_POINT_LIST;
  VkPipeline pipeline = VK_NULL_HANDLE;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  // Pixel centres (10.5, 5.5) and (21.5, 17.5): NDC x_f / 16 - 1.
  const float points[4] = {10.5f / 16 - 1, 5.5f / 16 - 1, 21.5f / 16 - 1, 17.5f / 16 - 1};
  HostBuffer vb = vertexBuffer(points, sizeof points);
  const std::vector<uint32_t> pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdDraw(cb, 2, 1, 0, 0);
  });
  ASSERT_EQ(pixels.size(), size_t(kW) * kH);
  const uint32_t want = rgba8(0.5, 0.5, 0.25, 1);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const bool point = (x == 10 && y == 5) || (x == 21 && y == 17);
      const uint32_t got = pixels[y * kW + x];
      EXPECT_TRUE(point ? near(got, want) : got == 0)
          << "pixel (" << x << ", " << y << "): " << std::hex << got << " want " << (point ? want : 0);
    }
  destroy(vb);
  destroy(color);
  vkDestroyPipeline(device, pipeline, nullptr);
}

INSTANTIATE_TEST_SUITE_P(BothPaths, DrawQuadShadingTest, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& i) { return i.param ? "Spmd" : "Fibers"; });

}  // namespace
}  // namespace vkrt::test
