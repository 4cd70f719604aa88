// InterpolateAtOffset / Sample / Centroid (GLSL.std.450 76-78, the InterpolationFunction capability that comes with
// sampleRateShading) in a fragment shader drawn through the API: each channel of the output interpolated at its own
// position, compared with the vertex colors interpolated here at that position (CTS draw.*.linear_interpolation.*).
#include <array>

#include "e2e/draw_fixture.hpp"

#include "draw_color.vert.spv.h"
#include "draw_interpolate_at.frag.spv.h"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

class DrawInterpolateAtTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.features.sampleRateShading = VK_TRUE;
    return o;
  }
};

// The vertex colors interpolated (w = 1: linearly) at framebuffer position (cx, cy).
std::array<double, 4> colorAt(const V (&t)[3], double cx, double cy, uint32_t w, uint32_t h) {
  double x[3], y[3];
  for (int i = 0; i < 3; ++i) x[i] = (double(t[i].x) + 1.0) * w / 2.0, y[i] = (double(t[i].y) + 1.0) * h / 2.0;
  const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
  const double l1 = ((cx - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (cy - y[0])) / area;
  const double l2 = ((x[1] - x[0]) * (cy - y[0]) - (cx - x[0]) * (y[1] - y[0])) / area;
  const double l0 = 1.0 - l1 - l2;
  return {l0 * t[0].r + l1 * t[1].r + l2 * t[2].r, l0 * t[0].g + l1 * t[1].g + l2 * t[2].g,
          l0 * t[0].b + l1 * t[1].b + l2 * t[2].b, 1.0};
}

TEST_F(DrawInterpolateAtTest, OffsetSampleAndCentroidInterpolateAtTheirPositions) {
  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  // Steep gradients: red changes by about 9 of 255 per pixel along x, so the offset's half pixel shows.
  static constexpr V kTri[3] = {{-0.9f, -0.9f, 1, 0, 0, 1}, {0.9f, -0.9f, 0, 1, 0, 1}, {-0.9f, 0.9f, 0, 0, 1, 1}};
  PipelineDesc d;
  d.vs = kSpv_draw_color_vert;
  d.vsBytes = sizeof kSpv_draw_color_vert;
  d.fs = kSpv_draw_interpolate_at_frag;
  d.fsBytes = sizeof kSpv_draw_interpolate_at_frag;
  d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  HostBuffer vb = vertexBuffer(kTri, sizeof kTri);
  auto pixels = render(color, nullptr, [&](VkCommandBuffer cb) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    VkDeviceSize off = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
    vkCmdDraw(cb, 3, 1, 0, 0);
  });
  int checked = 0, bad = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) {
      if (coverage(kTri[0], kTri[1], kTri[2], px, py) != 1) continue;
      // Red at the pixel centre + (-0.5, 0.4375); green at sample 0 (one sample: the centre); blue at the centroid
      // (a covered pixel of one sample: the centre).
      const auto offset = colorAt(kTri, px + 0.5 - 0.5, py + 0.5 + 0.4375, kW, kH);
      const auto centre = colorAt(kTri, px + 0.5, py + 0.5, kW, kH);
      const uint32_t want = rgba8(offset[0], centre[1], centre[2], 1.0);
      ++checked;
      if (!near(pixels[size_t(py) * kW + size_t(px)], want) && bad++ < 5)
        ADD_FAILURE() << "pixel " << px << "," << py << ": " << std::hex << pixels[size_t(py) * kW + size_t(px)]
                      << " want " << want;
    }
  EXPECT_EQ(bad, 0);
  EXPECT_GT(checked, 300);
  destroy(vb);
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
}

}  // namespace
}  // namespace vkrt::test
