// Colour attachment writes compiled into the fragment shader (abi::ColorMerge: the SPMD entry writes the fully
// covered quads of a one-attachment 8-bit UNorm target itself, the back end the rest) against the back end's: each
// scene is drawn twice on one device, once with pipelines whose blend state the merge takes (blending off, source
// alpha "over") and once with twins it does not take that compute the same values (ONE / ZERO blending; a
// CONSTANT_ALPHA factor of 1 where "over" has ONE), and the two images must be the same bytes. Smooth colours with
// components outside [0, 1], triangles whose edges cut quads, RGBA and BGRA targets, write masks. Run with the merge
// on (the default) and off (VKRT_COLOR_MERGE=0, read at device creation: both draws then take the back end). The
// merged bytes against the formulas: ColorMerge.* (the compiled writes), RasterQuadPath.* (the back end's).
#include <cstdlib>
#include <string>

#include "e2e/draw_fixture.hpp"

namespace vkrt::test {
namespace {

class DrawColorMergeTest : public DrawTest, public ::testing::WithParamInterface<bool> {
 protected:
  void SetUp() override {
    const char* was = std::getenv("VKRT_COLOR_MERGE");
    had_ = was != nullptr;
    if (had_) was_ = was;
    setenv("VKRT_COLOR_MERGE", GetParam() ? "1" : "0", 1);
    DrawTest::SetUp();
  }
  void TearDown() override {
    DrawTest::TearDown();
    if (had_)
      setenv("VKRT_COLOR_MERGE", was_.c_str(), 1);
    else
      unsetenv("VKRT_COLOR_MERGE");
  }

  VkPipeline pipeline(VkFormat format, const VkPipelineColorBlendAttachmentState& blend, float constantAlpha = 0) {
    PipelineDesc d = colorPipeline();
    d.colorFormat = format;
    d.blend = blend;
    d.blendConstants[3] = constantAlpha;
    VkPipeline p = VK_NULL_HANDLE;
    EXPECT_EQ(createPipeline(d, &p), VK_SUCCESS);
    return p;
  }

  // An opaque layer of two triangles, then three translucent ones over it (edges through the target's quads), in
  // the format's target cleared to `clear`: the pixels.
  std::vector<uint32_t> drawScene(VkFormat format, VkPipeline opaque, VkPipeline translucent, uint32_t clear) {
    const std::vector<Vertex> v = {
        // opaque: colours outside [0, 1] at the corners
        {-1.0f, -1.0f, -0.3f, 0.2f, 1.4f, 1.0f},
        {0.9f, -0.8f, 0.6f, 1.2f, 0.1f, 0.7f},
        {-0.7f, 0.85f, 0.25f, -0.1f, 0.5f, 0.3f},
        {0.95f, 0.9f, 1.1f, 0.4f, 0.8f, 1.0f},
        {0.9f, -0.8f, 0.6f, 1.2f, 0.1f, 0.7f},
        {-0.7f, 0.85f, 0.25f, -0.1f, 0.5f, 0.3f},
        // translucent: alpha from 0 to 1 (and beyond)
        {-1.0f, -0.2f, 0.9f, 0.1f, 0.1f, 0.0f},
        {1.0f, -0.6f, 0.1f, 0.9f, 0.2f, 1.0f},
        {0.1f, 1.0f, 0.2f, 0.3f, 1.0f, 0.55f},
        {-0.55f, -1.0f, 1.3f, 1.0f, -0.2f, 0.4f},
        {0.6f, 0.15f, 0.0f, 0.5f, 0.5f, 1.25f},
        {-0.9f, 0.7f, 0.7f, 0.7f, 0.7f, 0.8f},
        {-1.0f, -1.0f, 0.5f, 0.5f, 0.0f, 0.33f},
        {1.0f, -1.0f, 0.5f, 0.0f, 0.5f, 0.66f},
        {0.0f, 1.0f, 0.0f, 0.5f, 0.5f, 0.5f},
    };
    HostBuffer vb = vertexBuffer(v.data(), v.size() * sizeof(Vertex));
    Target color = createTarget(format, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                VK_IMAGE_ASPECT_COLOR_BIT);
    std::vector<uint32_t> pixels = render(
        color, nullptr,
        [&](VkCommandBuffer cb) {
          VkDeviceSize off = 0;
          vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
          vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, opaque);
          vkCmdDraw(cb, 6, 1, 0, 0);
          vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, translucent);
          vkCmdDraw(cb, 9, 1, 6, 0);
        },
        clear);
    destroy(color);
    destroy(vb);
    return pixels;
  }

  bool had_ = false;
  std::string was_;
};

constexpr VkPipelineColorBlendAttachmentState blendState(VkBool32 enable, VkBlendFactor srcColor,
                                                         VkBlendFactor dstColor, VkBlendFactor srcAlpha,
                                                         VkBlendFactor dstAlpha, VkColorComponentFlags mask = 0xF) {
  return {enable, srcColor, dstColor, VK_BLEND_OP_ADD, srcAlpha, dstAlpha, VK_BLEND_OP_ADD, mask};
}

TEST_P(DrawColorMergeTest, MergedWritesAreTheBackEndsBytes) {
  const auto one = VK_BLEND_FACTOR_ONE, zero = VK_BLEND_FACTOR_ZERO, srcAlpha = VK_BLEND_FACTOR_SRC_ALPHA;
  const auto inv = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA, constant = VK_BLEND_FACTOR_CONSTANT_ALPHA;
  for (VkFormat format : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM})
    for (VkColorComponentFlags mask : {0xFu, 0x5u}) {
      SCOPED_TRACE("format " + std::to_string(format) + " write mask " + std::to_string(mask));
      // The merge's (blending off; "over" with alpha as coverage) and their twins'.
      VkPipeline opaque = pipeline(format, blendState(VK_FALSE, one, zero, one, zero, mask));
      VkPipeline over = pipeline(format, blendState(VK_TRUE, srcAlpha, inv, one, inv, mask));
      VkPipeline opaqueTwin = pipeline(format, blendState(VK_TRUE, one, zero, one, zero, mask));
      VkPipeline overTwin = pipeline(format, blendState(VK_TRUE, srcAlpha, inv, constant, inv, mask), 1.0f);
      const uint32_t clear = 0x80402010u;
      const std::vector<uint32_t> merged = drawScene(format, opaque, over, clear);
      const std::vector<uint32_t> twin = drawScene(format, opaqueTwin, overTwin, clear);
      ASSERT_EQ(merged.size(), size_t(kW) * kH);
      int differ = 0;
      for (size_t i = 0; i < merged.size(); ++i)
        if (merged[i] != twin[i] && ++differ <= 5)
          ADD_FAILURE() << "pixel (" << i % kW << ", " << i / kW << "): " << std::hex << merged[i] << " against "
                        << twin[i];
      EXPECT_EQ(differ, 0);
      // The scene is not empty: the clear colour is left only outside the triangles.
      int cleared = 0;
      for (uint32_t p : merged) cleared += p == clear;
      EXPECT_LT(cleared, int(kW * kH / 4));
      for (VkPipeline p : {opaque, over, opaqueTwin, overTwin}) vkDestroyPipeline(device, p, nullptr);
    }
}

INSTANTIATE_TEST_SUITE_P(MergeOnAndOff, DrawColorMergeTest, ::testing::Bool());

}  // namespace
}  // namespace vkrt::test
