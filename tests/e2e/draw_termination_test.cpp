// shaderDemoteToHelperInvocation and shaderTerminateInvocation (Vulkan 1.3 features): a fragment shader that writes
// its color and then demotes or terminates some fragments; the target keeps the clear color wherever that happened.
#include "e2e/draw_fixture.hpp"

#include "draw_color.vert.spv.h"
#include "draw_demote_terminate.frag.spv.h"

namespace vkrt::test {
namespace {

using V = DrawTest::Vertex;

class DrawTerminationTest : public DrawTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = DrawTest::options();
    o.features13.shaderDemoteToHelperInvocation = VK_TRUE;
    o.features13.shaderTerminateInvocation = VK_TRUE;
    return o;
  }
};

TEST_F(DrawTerminationTest, DemotedAndTerminatedFragmentsWriteNothing) {
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f13};
  vkGetPhysicalDeviceFeatures2(physicalDevice, &f2);
  EXPECT_TRUE(f13.shaderDemoteToHelperInvocation);
  EXPECT_TRUE(f13.shaderTerminateInvocation);

  Target color = createTarget(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
  PipelineDesc d;
  d.vs = kSpv_draw_color_vert;
  d.vsBytes = sizeof kSpv_draw_color_vert;
  d.fs = kSpv_draw_demote_terminate_frag;
  d.fsBytes = sizeof kSpv_draw_demote_terminate_frag;
  d.bindings = {{0, sizeof(V), VK_VERTEX_INPUT_RATE_VERTEX}};
  d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 8}};
  VkPipeline pipeline;
  ASSERT_EQ(createPipeline(d, &pipeline), VK_SUCCESS);
  // One triangle covering the whole target, in a flat red (the shader's final write swizzles it to blue).
  const V tri[3] = {{-1, -1, 1, 0, 0, 1}, {3, -1, 1, 0, 0, 1}, {-1, 3, 1, 0, 0, 1}};
  HostBuffer vb = vertexBuffer(tri, sizeof tri);
  const uint32_t clear = 0xFF202020u;
  auto pixels = render(
      color, nullptr,
      [&](VkCommandBuffer cb) {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        VkDeviceSize off = 0;
        vkCmdBindVertexBuffers(cb, 0, 1, &vb.buffer, &off);
        vkCmdDraw(cb, 3, 1, 0, 0);
      },
      clear);
  // Pixel centres are at (px + 0.5, py + 0.5): demoted for px < 16, terminated for py < 8, else blue.
  int mismatches = 0;
  for (int py = 0; py < int(kH); ++py)
    for (int px = 0; px < int(kW); ++px) {
      const uint32_t want = px < 16 || py < 8 ? clear : 0xFFFF0000u;
      const uint32_t got = pixels[size_t(py) * kW + px];
      if (got != want && ++mismatches <= 5)
        ADD_FAILURE() << "pixel (" << px << ", " << py << "): " << std::hex << got << " want " << want;
    }
  EXPECT_EQ(mismatches, 0);
  destroy(vb);
  vkDestroyPipeline(device, pipeline, nullptr);
  destroy(color);
}

}  // namespace
}  // namespace vkrt::test
