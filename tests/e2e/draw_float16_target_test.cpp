// An R16G16B16A16_SFLOAT colour attachment (an HDR target; the back end's float16 quad path, raster/backend.cpp
// half4Quad): blending with source alpha over the cleared target, components outside [0, 1] kept (a float format is
// not clamped), the results rounded to half precision: every pixel's four halves against the formula computed here,
// and a write mask that keeps the cleared components.
#include <cmath>
#include <cstring>

#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

class DrawFloat16TargetTest : public DrawTest {};

// The half nearest to a float of the normal half range (to nearest even), as a float; and a half's value.
float roundToHalf(float f) {
  int e;
  std::frexp(f, &e);  // f = m 2^e, m in [0.5, 1): 11 significant bits are a step of 2^(e - 11)
  return std::ldexp(std::nearbyint(std::ldexp(f, 11 - e)), e - 11);
}
float halfValue(uint16_t h) {
  const int e = h >> 10 & 31, m = h & 1023;
  const float v = e == 0 ? std::ldexp(float(m), -24) : std::ldexp(float(m | 1024), e - 25);
  return h >> 15 ? -v : v;
}

TEST_F(DrawFloat16TargetTest, BlendedColoursStayOutsideZeroToOneAndRoundToHalf) {
  for (VkColorComponentFlags mask : {0xFu, 0x9u}) {
    SCOPED_TRACE("write mask " + std::to_string(mask));
    PipelineDesc d = colorPipeline();
    d.colorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.blend = {VK_TRUE,
               VK_BLEND_FACTOR_SRC_ALPHA,
               VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
               VK_BLEND_OP_ADD,
               VK_BLEND_FACTOR_ONE,
               VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
               VK_BLEND_OP_ADD,
               mask};
    VkPipeline pipeline;
    ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
    Target color =
        createTarget(VK_FORMAT_R16G16B16A16_SFLOAT,
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    // A constant colour over the whole target (every quad fully covered), then a triangle over part of it (edges
    // through quads): (6, -1.5, 0.75, 0.25) and (0.5, 2, -4, 0.75).
    const Vertex tris[6] = {{-1, -1, 6.0f, -1.5f, 0.75f, 0.25f},     {3, -1, 6.0f, -1.5f, 0.75f, 0.25f},
                            {-1, 3, 6.0f, -1.5f, 0.75f, 0.25f},      {-0.7f, -0.9f, 0.5f, 2.0f, -4.0f, 0.75f},
                            {0.8f, -0.3f, 0.5f, 2.0f, -4.0f, 0.75f}, {-0.2f, 0.9f, 0.5f, 2.0f, -4.0f, 0.75f}};
    HostBuffer vb = vertexBuffer(tris, sizeof tris);
    const uint32_t clear = 0xFF804020u;  // (32, 64, 128, 255) / 255
    const std::vector<uint32_t> words = render(
        color, nullptr,
        [&](VkCommandBuffer cb) {
          vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
          VkDeviceSize off = 0;
          vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
          vkCmdDraw(cb, 6, 1, 0, 0);
        },
        clear);
    ASSERT_EQ(words.size(), size_t(kW) * kH * 2);
    // The formula: d' = s a + d (1 - a) per colour component, a' = a + d_a (1 - a), each result rounded to half;
    // masked components keep the cleared value.
    auto blend = [&](const float dst[4], const float src[4], float out[4]) {
      for (int c = 0; c < 4; ++c) {
        const float sf = c == 3 ? 1.0f : src[3], df = 1.0f - src[3];
        const float a = src[c] * sf, b = dst[c] * df;
        out[c] = mask >> c & 1 ? roundToHalf(a + b) : dst[c];
      }
    };
    float cleared[4];
    for (int c = 0; c < 4; ++c) cleared[c] = roundToHalf(float((clear >> (8 * c)) & 0xFF) / 255.0f);
    const float first[4] = {6.0f, -1.5f, 0.75f, 0.25f}, second[4] = {0.5f, 2.0f, -4.0f, 0.75f};
    float under[4], over[4];
    blend(cleared, first, under);
    blend(under, second, over);
    const std::array<Vertex, 3> tri = {tris[3], tris[4], tris[5]};
    int mismatches = 0, inside = 0;
    for (uint32_t y = 0; y < kH; ++y)
      for (uint32_t x = 0; x < kW; ++x) {
        const int cov = coverage(tri[0], tri[1], tri[2], int(x), int(y));
        if (cov < 0) continue;  // near an edge
        inside += cov;
        uint16_t h[4];
        std::memcpy(h, &words[2 * (size_t(y) * kW + x)], 8);
        const float* want = cov ? over : under;
        for (int c = 0; c < 4; ++c)
          if (halfValue(h[c]) != want[c] && ++mismatches <= 5)
            ADD_FAILURE() << "pixel (" << x << ", " << y << ") component " << c << ": " << halfValue(h[c]) << " want "
                          << want[c];
      }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(inside, 100);
    EXPECT_GT(under[0], 1.0f);  // outside [0, 1] (a UNorm target would clamp)
    if (mask & 4) {
      EXPECT_LT(over[2], 0.0f);
    }
    destroy(vb);
    destroy(color);
    vkDestroyPipeline(device, pipeline, nullptr);
  }
}

}  // namespace
}  // namespace vkrt::test
