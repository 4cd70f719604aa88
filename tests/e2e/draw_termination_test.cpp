// shaderDemoteToHelperInvocation and shaderTerminateInvocation (Vulkan 1.3 features): a fragment shader that writes
// its color and then demotes or terminates some fragments; the target keeps the clear color wherever that happened.
#include "e2e/draw_fixture.hpp"

#include "draw_demote_terminate.frag.spv.h"

namespace vkrt::test {
namespace {

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

  // One triangle covering the whole target, in a flat red (the shader's final write swizzles it to blue).
  const float red[4] = {1, 0, 0, 1};
  const uint32_t clear = 0xFF202020u;
  auto pixels = drawFullScreen(kSpv_draw_demote_terminate_frag, sizeof kSpv_draw_demote_terminate_frag, red, clear);
  ASSERT_EQ(pixels.size(), size_t(kW) * kH);
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
}

}  // namespace
}  // namespace vkrt::test
