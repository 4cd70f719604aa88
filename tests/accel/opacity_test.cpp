// Opacity (geometry flag, instance force flags, ray flags), opacity culling, and the ray flags that skip or stop.
#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

struct Outcome {
  bool hit;
  float t;
  size_t anyHitCalls;
};

Outcome run(const Tlas& tlas, const Ray& ray, AnyHitResult answer = AnyHitResult::Accept) {
  Recorder rec;
  rec.onAnyHit = [&](const HitInfo&) { return answer; };
  Traced r = traceOnce(tlas, ray, rec);
  return {r.hit, r.hit ? r.info.t : -1.0f, rec.anyHits.size()};
}

TEST(AccelOpacity, GeometryFlagDecidesWhetherTheAnyHitShaderRuns) {
  auto opaque = sceneOf({quad(5, kGeometryOpaque)});
  auto noOpaque = sceneOf({quad(5, 0)});
  Outcome o = run(*opaque, rayUp(), AnyHitResult::Ignore);
  EXPECT_TRUE(o.hit);
  EXPECT_EQ(o.anyHitCalls, 0u);
  o = run(*noOpaque, rayUp(), AnyHitResult::Ignore);
  EXPECT_FALSE(o.hit);
  EXPECT_EQ(o.anyHitCalls, 1u);
  o = run(*noOpaque, rayUp(), AnyHitResult::Accept);
  EXPECT_TRUE(o.hit);
  EXPECT_NEAR(o.t, 5.0f, kTol);
  EXPECT_EQ(o.anyHitCalls, 1u);
}

TEST(AccelOpacity, InstanceForceFlagsThenRayFlagsOverride) {
  auto opaqueBlas = makeBlas({quad(5, kGeometryOpaque)});
  auto noOpaqueBlas = makeBlas({quad(5, 0)});
  struct Case {
    std::shared_ptr<Blas> blas;
    uint32_t instanceFlags, rayFlags;
    bool anyHitRuns;
  } cases[] = {
      {noOpaqueBlas, kInstanceForceOpaque, 0, false},
      {opaqueBlas, kInstanceForceNoOpaque, 0, true},
      {noOpaqueBlas, 0, kRayOpaque, false},
      {opaqueBlas, 0, kRayNoOpaque, true},
      {opaqueBlas, kInstanceForceNoOpaque, kRayOpaque, false},  // the ray's flag overrides the instance's
      {noOpaqueBlas, kInstanceForceOpaque, kRayNoOpaque, true},
      {opaqueBlas, kInstanceForceOpaque, 0, false},
      {noOpaqueBlas, kInstanceForceNoOpaque, 0, true},
  };
  for (size_t i = 0; i < std::size(cases); ++i) {
    const Case& c = cases[i];
    auto tlas = makeTlas({instanceOf(c.blas, c.instanceFlags)});
    Outcome o = run(*tlas, rayUp(c.rayFlags), AnyHitResult::Ignore);
    EXPECT_EQ(o.anyHitCalls, c.anyHitRuns ? 1u : 0u) << "case " << i;
    EXPECT_EQ(o.hit, !c.anyHitRuns) << "case " << i;  // Ignore drops it; an opaque one is committed
  }
}

TEST(AccelOpacity, CullOpaqueAndCullNoOpaque) {
  // An opaque quad at 3 and a non-opaque one at 5, in two geometries of one Blas.
  auto blas = makeBlas({quad(3, kGeometryOpaque), quad(5, 0)});
  auto tlas = makeTlas({instanceOf(blas)});
  Outcome o = run(*tlas, rayUp(kRayCullOpaque));
  EXPECT_TRUE(o.hit);
  EXPECT_NEAR(o.t, 5.0f, kTol);
  EXPECT_EQ(o.anyHitCalls, 1u);
  o = run(*tlas, rayUp(kRayCullNoOpaque));
  EXPECT_TRUE(o.hit);
  EXPECT_NEAR(o.t, 3.0f, kTol);
  EXPECT_EQ(o.anyHitCalls, 0u);  // the non-opaque candidate is dropped before its any-hit shader
  // Culling applies to the opacity after the instance's force flags.
  auto forced = makeTlas({instanceOf(blas, kInstanceForceNoOpaque)});
  o = run(*forced, rayUp(kRayCullOpaque));
  EXPECT_TRUE(o.hit);
  EXPECT_NEAR(o.t, 3.0f, kTol);
  o = run(*forced, rayUp(kRayCullNoOpaque));
  EXPECT_FALSE(o.hit);
  EXPECT_EQ(o.anyHitCalls, 0u);
  auto forcedOpaque = makeTlas({instanceOf(blas, kInstanceForceOpaque)});
  EXPECT_FALSE(run(*forcedOpaque, rayUp(kRayCullOpaque)).hit);
}

TEST(AccelOpacity, TerminateOnFirstHitStopsAtTheFirstCommit) {
  // Opaque quads at 3, 5 and 7: the hit is one of them (not necessarily the closest).
  auto opaque = sceneOf({quads({7, 3, 5})});
  Traced r = traceOnce(*opaque, rayUp(kRayTerminateOnFirstHit));
  ASSERT_TRUE(r.hit);
  const float depthOfQuad[3] = {7, 3, 5};
  EXPECT_EQ(r.info.primitiveIndex % 2, 0u);  // (0.3, -0.4): each quad's first triangle
  ASSERT_LT(r.info.primitiveIndex, 6u);
  EXPECT_NEAR(r.info.t, depthOfQuad[r.info.primitiveIndex / 2], kTol);
  EXPECT_EQ(r.info.hitKind, kHitKindBackFacingTriangle);
  // Non-opaque: the first accepted candidate ends it; ignored ones before it do not.
  auto noOpaque = sceneOf({quads({7, 3, 5}, 0)});
  Recorder rec;
  r = traceOnce(*noOpaque, rayUp(kRayTerminateOnFirstHit), rec);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(rec.anyHits.size(), 1u);
  EXPECT_EQ(r.info.t, rec.anyHits[0].t);
  EXPECT_EQ(r.info.primitiveIndex, rec.anyHits[0].primitiveIndex);
  Recorder second;
  second.onAnyHit = [&](const HitInfo&) {
    return second.anyHits.size() == 1 ? AnyHitResult::Ignore : AnyHitResult::Accept;
  };
  r = traceOnce(*noOpaque, rayUp(kRayTerminateOnFirstHit), second);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(second.anyHits.size(), 2u);
  EXPECT_EQ(r.info.t, second.anyHits[1].t);
  Recorder none;
  none.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
  EXPECT_FALSE(traceOnce(*noOpaque, rayUp(kRayTerminateOnFirstHit), none).hit);
  EXPECT_EQ(none.anyHits.size(), 3u);
  // Whatever the order of the traversal: a box in front whose shader commits far behind everything, and the
  // non-opaque quads. Without termination both the box's shader and a quad's any-hit shader would run.
  auto mixed = sceneOf({quads({7, 3, 5}, 0), boxes({{-1, -1, 1, 1, 1, 1.5f}})});
  Recorder once;
  once.onIntersect = [](ProceduralCandidate& c) { c.commit(50, 1, false); };
  r = traceOnce(*mixed, rayUp(kRayTerminateOnFirstHit), once);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(once.anyHits.size() + once.boxes.size(), 1u);
  EXPECT_EQ(r.info.triangle, once.boxes.empty());
  // Barycentrics and the rest come with the hit, as for a closest hit.
  r = traceOnce(*opaque, rayUp(kRayTerminateOnFirstHit | kRayCullFrontFacingTriangles));
  ASSERT_TRUE(r.hit);
  Traced closest = traceOnce(*opaque, rayUp());
  EXPECT_NEAR(r.info.barycentrics[0], closest.info.barycentrics[0], kTol);
  EXPECT_NEAR(r.info.barycentrics[1], closest.info.barycentrics[1], kTol);
  EXPECT_FALSE(traceOnce(*opaque, rayUp(kRayTerminateOnFirstHit | kRayCullBackFacingTriangles)).hit);
}

TEST(AccelOpacity, SkipClosestHitShaderLeavesTraversalAlone) {
  auto tlas = sceneOf({quads({7, 3, 5}, 0)});
  Recorder a, b;
  Traced x = traceOnce(*tlas, rayUp(), a);
  Traced y = traceOnce(*tlas, rayUp(kRaySkipClosestHitShader), b);
  ASSERT_TRUE(x.hit && y.hit);
  EXPECT_EQ(x.info.t, y.info.t);
  EXPECT_EQ(x.info.primitiveIndex, y.info.primitiveIndex);
  EXPECT_EQ(a.anyHits.size(), b.anyHits.size());
}

TEST(AccelOpacity, SkipTrianglesAndSkipAabbs) {
  // A quad at 5 and a box between 2 and 3, in one Blas; the intersection shader commits the box's entry.
  auto tlas = sceneOf({quad(5), boxes({{-1, -1, 2, 1, 1, 3}})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) { c.commit(2.0f, 9, false); };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_FALSE(r.info.triangle);
  EXPECT_EQ(r.info.hitKind, 9u);
  r = traceOnce(*tlas, rayUp(kRaySkipAabbs), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_TRUE(r.info.triangle);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  rec.boxes.clear();
  r = traceOnce(*tlas, rayUp(kRaySkipTriangles), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_FALSE(r.info.triangle);
  EXPECT_EQ(rec.boxes.size(), 1u);
  // With nothing but triangles skipped and a shader that reports nothing: a miss.
  Recorder silent;
  EXPECT_FALSE(traceOnce(*tlas, rayUp(kRaySkipTriangles), silent).hit);
  EXPECT_EQ(silent.boxes.size(), 1u);
  rec.boxes.clear();
  EXPECT_FALSE(traceOnce(*sceneOf({boxes({{-1, -1, 2, 1, 1, 3}})}), rayUp(kRaySkipAabbs), rec).hit);
  EXPECT_TRUE(rec.boxes.empty());
}

}  // namespace
}  // namespace vkrt::accel::test
