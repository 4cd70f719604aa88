// The speed rule: a ray that can meet only opaque triangles, with no ray or instance flag that asks for per-candidate
// work, runs without any filter callback (as raw rtcIntersect1 does). White-box: the decision itself.
#include "accel/scenes.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel::test {
namespace {

bool filtered(const Tlas& tlas, uint32_t rayFlags) {
  return detail::needsTriangleFilter(tlas.impl().summary, rayFlags);
}

TEST(AccelFastPath, OpaqueTrianglesNeedNoFilterUnlessAFlagAsks) {
  auto opaque = makeBlas({quad(5), boxes({{0, 0, 0, 1, 1, 1}}, 0)});
  auto tlas = makeTlas({instanceOf(opaque), translated(opaque, 3, 0, 0)});
  for (uint32_t flags : {0u, uint32_t(kRayOpaque), uint32_t(kRaySkipClosestHitShader), uint32_t(kRaySkipAabbs),
                         uint32_t(kRayCullNoOpaque), uint32_t(kRaySkipTriangles),
                         uint32_t(kRaySkipTriangles | kRayCullBackFacingTriangles | kRayNoOpaque)})
    EXPECT_FALSE(filtered(*tlas, flags)) << std::hex << flags;
  for (uint32_t flags : {uint32_t(kRayCullBackFacingTriangles), uint32_t(kRayCullFrontFacingTriangles),
                         uint32_t(kRayNoOpaque), uint32_t(kRayCullOpaque), uint32_t(kRayTerminateOnFirstHit)})
    EXPECT_TRUE(filtered(*tlas, flags)) << std::hex << flags;
  // Facing culling where every instance disables it: nothing to cull, no filter.
  auto noCull = makeTlas({instanceOf(opaque, kInstanceTriangleFacingCullDisable)});
  EXPECT_FALSE(filtered(*noCull, kRayCullBackFacingTriangles));
}

TEST(AccelFastPath, NonOpaqueTrianglesAfterInstanceFlagsNeedIt) {
  auto opaque = makeBlas({quad(5)});
  auto noOpaque = makeBlas({quad(5, 0)});
  EXPECT_TRUE(filtered(*makeTlas({instanceOf(noOpaque)}), 0));
  EXPECT_FALSE(filtered(*makeTlas({instanceOf(noOpaque)}), kRayOpaque));
  EXPECT_TRUE(filtered(*makeTlas({instanceOf(noOpaque)}), kRayCullNoOpaque));
  EXPECT_FALSE(filtered(*makeTlas({instanceOf(noOpaque, kInstanceForceOpaque)}), 0));
  EXPECT_TRUE(filtered(*makeTlas({instanceOf(opaque, kInstanceForceNoOpaque)}), 0));
  EXPECT_FALSE(filtered(*makeTlas({instanceOf(opaque, kInstanceForceNoOpaque)}), kRayOpaque));
  // An instance no ray can see (mask 0), an inactive one, and boxes only: no triangles to filter.
  EXPECT_FALSE(filtered(*makeTlas({instanceOf(noOpaque, 0, 0), instanceOf(opaque), instanceOf(nullptr)}), 0));
  const auto boxes1 = makeBlas({boxes({{0, 0, 0, 1, 1, 1}}, 0)});
  auto boxesOnly = makeTlas({instanceOf(boxes1)});
  EXPECT_FALSE(filtered(*boxesOnly, kRayNoOpaque | kRayCullBackFacingTriangles | kRayTerminateOnFirstHit));
}

}  // namespace
}  // namespace vkrt::accel::test
