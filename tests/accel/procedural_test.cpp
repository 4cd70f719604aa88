// Box primitives: when the intersection shader runs, what it sees, and its commits through ProceduralCandidate.
#include <algorithm>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// The analytic entry t of a ray along +z from z = 0 into a box [z0, z1] is z0.
const std::array<float, 6> kBoxA = {-1, -1, 4, 1, 1, 6};

TEST(AccelProcedural, IntersectionShaderRunsForBoxesTheRayEnters) {
  auto tlas = sceneOf({boxes({kBoxA, {5, 5, 4, 6, 6, 6}})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) {
    EXPECT_EQ(c.tMin(), 0.0f);
    EXPECT_EQ(c.tMax(), 1000.0f);
    EXPECT_TRUE(c.opaque());
    c.commit(4.5f, 7, false);
  };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(rec.boxes.size(), 1u);  // the other box is off the ray
  const HitInfo& seen = rec.boxes[0];
  EXPECT_FALSE(seen.triangle);
  EXPECT_EQ(seen.primitiveIndex, 0u);
  EXPECT_EQ(seen.geometryIndex, 0u);
  EXPECT_EQ(seen.instanceIndex, 0u);
  EXPECT_NEAR(seen.objectRayOrigin[0], 0.3f, kTol);
  EXPECT_NEAR(seen.objectRayDirection[2], 1.0f, kTol);
  EXPECT_FALSE(r.info.triangle);
  EXPECT_EQ(r.info.t, 4.5f);
  EXPECT_EQ(r.info.hitKind, 7u);
  EXPECT_EQ(r.info.primitiveIndex, 0u);
  // A shader that reports nothing: a miss. Beside the boxes: no call.
  Recorder silent;
  EXPECT_FALSE(traceOnce(*tlas, rayUp(), silent).hit);
  EXPECT_EQ(silent.boxes.size(), 1u);
  EXPECT_FALSE(traceOnce(*tlas, rayUp(0, 3, 3), silent).hit);
  EXPECT_EQ(silent.boxes.size(), 1u);
  // The second box, through its primitive index.
  r = traceOnce(*tlas, rayUp(0, 5.5f, 5.5f), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 1u);
}

TEST(AccelProcedural, SeveralReportsPerPrimitiveAndTMaxFollowsCommits) {
  auto tlas = sceneOf({boxes({kBoxA})});
  Recorder rec;
  std::vector<float> tMaxSeen;
  rec.onIntersect = [&](ProceduralCandidate& c) {
    // As the executor does: a report outside [tMin(), tMax()] is not a hit.
    for (float t : {5.5f, 4.5f, 5.0f, 4.8f}) {
      tMaxSeen.push_back(c.tMax());
      if (t >= c.tMin() && t <= c.tMax()) c.commit(t, uint32_t(t * 10), false);
    }
    tMaxSeen.push_back(c.tMax());
  };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.t, 4.5f);
  EXPECT_EQ(r.info.hitKind, 45u);
  EXPECT_EQ(tMaxSeen, (std::vector<float>{1000.0f, 5.5f, 4.5f, 4.5f, 4.5f}));
  // A commit outside the interval is refused by commit() itself too.
  Recorder outside;
  outside.onIntersect = [](ProceduralCandidate& c) {
    c.commit(2000.0f, 1, false);
    c.commit(-1.0f, 2, false);
  };
  EXPECT_FALSE(traceOnce(*tlas, rayUp(), outside).hit);
}

TEST(AccelProcedural, TMaxSeesTriangleCommitsAndBoxesBehindTheClosestHitAreSkipped) {
  // An opaque quad at 3 in front of the box (4..6): whichever the traversal meets first, the box's shader never
  // commits behind the quad, and if it runs after the quad was committed its tMax() is 3.
  auto tlas = sceneOf({quad(3), boxes({kBoxA})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) {
    EXPECT_TRUE(c.tMax() == 3.0f || c.tMax() == 1000.0f) << c.tMax();
    if (c.tMax() >= 4.5f) c.commit(4.5f, 1, false);
  };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_TRUE(r.info.triangle);
  EXPECT_NEAR(r.info.t, 3.0f, kTol);
  // A box commit in front of a triangle wins.
  auto front = sceneOf({quad(5), boxes({{-1, -1, 2, 1, 1, 3}})});
  Recorder near;
  near.onIntersect = [](ProceduralCandidate& c) { c.commit(2.5f, 3, false); };
  r = traceOnce(*front, rayUp(), near);
  ASSERT_TRUE(r.hit);
  EXPECT_FALSE(r.info.triangle);
  EXPECT_EQ(r.info.t, 2.5f);
  EXPECT_EQ(r.info.hitKind, 3u);
  EXPECT_EQ(r.info.geometryIndex, 1u);
}

TEST(AccelProcedural, TerminateEndsTheTraversal) {
  // Three boxes along the ray; the first shader to run commits and terminates: no other shader runs.
  auto tlas = sceneOf({boxes({{-1, -1, 2, 1, 1, 3}, {-1, -1, 4, 1, 1, 5}, {-1, -1, 6, 1, 1, 7}})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) {
    c.commit(c.info().primitiveIndex * 2 + 2.5f, 100 + c.info().primitiveIndex, true);
  };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(rec.boxes.size(), 1u);
  EXPECT_EQ(r.info.primitiveIndex, rec.boxes[0].primitiveIndex);
  EXPECT_EQ(r.info.hitKind, 100 + r.info.primitiveIndex);
  EXPECT_EQ(r.info.t, r.info.primitiveIndex * 2 + 2.5f);
  // Without terminate every box runs (those behind a commit may be skipped), and the closest wins.
  Recorder all;
  all.onIntersect = [](ProceduralCandidate& c) {
    c.commit(c.info().primitiveIndex * 2 + 2.5f, 100 + c.info().primitiveIndex, false);
  };
  r = traceOnce(*tlas, rayUp(), all);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.t, 2.5f);
  EXPECT_EQ(r.info.hitKind, 100u);
  // TerminateOnFirstHit: the first commit ends it, whatever the shader asked.
  Recorder first;
  first.onIntersect = all.onIntersect;
  r = traceOnce(*tlas, rayUp(kRayTerminateOnFirstHit), first);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(first.boxes.size(), 1u);
  EXPECT_EQ(r.info.primitiveIndex, first.boxes[0].primitiveIndex);
  EXPECT_EQ(r.info.hitKind, 100 + r.info.primitiveIndex);
  // ... and a shader that reports nothing lets the next one run.
  Recorder skipFirst;
  skipFirst.onIntersect = [&](ProceduralCandidate& c) {
    if (skipFirst.boxes.size() > 1) c.commit(c.info().primitiveIndex * 2 + 2.5f, 5, false);
  };
  r = traceOnce(*tlas, rayUp(kRayTerminateOnFirstHit), skipFirst);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(skipFirst.boxes.size(), 2u);
}

TEST(AccelProcedural, CandidateIntervalIncludesBothEnds) {
  // "tmin <= t <= tmax" for boxes (triangles exclude both ends, see AccelTraversal).
  auto tlas = sceneOf({boxes({kBoxA})});
  Recorder rec;
  Ray r = rayUp();
  r.tMax = 4.0f;  // the box starts at t = 4
  traceOnce(*tlas, r, rec);
  EXPECT_EQ(rec.boxes.size(), 1u);
  r.tMax = 3.99f;
  traceOnce(*tlas, r, rec);
  EXPECT_EQ(rec.boxes.size(), 1u);
  r.tMax = 100;
  r.tMin = 6.0f;  // the box ends at t = 6
  traceOnce(*tlas, r, rec);
  EXPECT_EQ(rec.boxes.size(), 2u);
  r.tMin = 6.01f;
  traceOnce(*tlas, r, rec);
  EXPECT_EQ(rec.boxes.size(), 2u);
  // A ray starting inside the box meets it.
  traceOnce(*tlas, rayFrom(0, 0, 5, 1, 0, 0), rec);
  EXPECT_EQ(rec.boxes.size(), 3u);
  // A degenerate (flat) box is still a candidate, and a ray parallel to an axis outside the box's slab is not.
  auto flat = sceneOf({boxes({{-1, -1, 4, 1, 1, 4}})});
  Recorder f;
  traceOnce(*flat, rayUp(), f);
  EXPECT_EQ(f.boxes.size(), 1u);
  traceOnce(*tlas, rayFrom(0, 2, 5, 1, 0, 0), f);
  EXPECT_EQ(f.boxes.size(), 1u);
}

TEST(AccelProcedural, OpacityOfBoxes) {
  auto opaque = sceneOf({boxes({kBoxA}, kGeometryOpaque)});
  auto noOpaque = sceneOf({boxes({kBoxA}, 0)});
  auto seenOpaque = [](const Tlas& tlas, uint32_t flags) -> int {
    Recorder rec;
    int result = -1;
    rec.onIntersect = [&](ProceduralCandidate& c) { result = c.opaque(); };
    traceOnce(tlas, rayUp(flags), rec);
    return result;  // -1: the shader did not run
  };
  EXPECT_EQ(seenOpaque(*opaque, 0), 1);
  EXPECT_EQ(seenOpaque(*noOpaque, 0), 0);
  EXPECT_EQ(seenOpaque(*opaque, kRayNoOpaque), 0);
  EXPECT_EQ(seenOpaque(*noOpaque, kRayOpaque), 1);
  EXPECT_EQ(seenOpaque(*opaque, kRayCullOpaque), -1);
  EXPECT_EQ(seenOpaque(*noOpaque, kRayCullNoOpaque), -1);
  EXPECT_EQ(seenOpaque(*opaque, kRayCullNoOpaque), 1);
  EXPECT_EQ(seenOpaque(*noOpaque, kRayCullOpaque), 0);
  auto blas = makeBlas({boxes({kBoxA}, 0)});
  EXPECT_EQ(seenOpaque(*makeTlas({instanceOf(blas, kInstanceForceOpaque)}), 0), 1);
  EXPECT_EQ(seenOpaque(*makeTlas({instanceOf(blas, kInstanceForceOpaque)}), kRayCullOpaque), -1);
  // Facing flags do not apply to boxes.
  EXPECT_EQ(seenOpaque(*opaque, kRayCullBackFacingTriangles), 1);
  EXPECT_EQ(seenOpaque(*opaque, kRayCullFrontFacingTriangles), 1);
}

TEST(AccelProcedural, TransformedInstanceOfBoxes) {
  // Scale 2 and translate (10, 0, 0): the box [-1, 1]^2 x [4, 6] is at world x in [8, 12], z in [8, 12].
  Instance in = instanceOf(makeBlas({boxes({kBoxA})}));
  const float m[3][4] = {{2, 0, 0, 10}, {0, 2, 0, 0}, {0, 0, 2, 0}};
  std::copy(&m[0][0], &m[0][0] + 12, &in.transform[0][0]);
  in.customIndex = 42;
  auto tlas = makeTlas({instanceOf(nullptr), in});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) {
    // The shader intersects in object space: object z = 4 is reached at t with 0 + t * 0.5 = 4.
    const HitInfo& h = c.info();
    const float t = (4 - h.objectRayOrigin[2]) / h.objectRayDirection[2];
    c.commit(t, 1, false);
  };
  Traced r = traceOnce(*tlas, rayFrom(11, 1, 0, 0, 0, 1), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 8.0f, kTol);
  EXPECT_EQ(r.info.instanceIndex, 1u);
  EXPECT_EQ(r.info.customIndex, 42u);
  ASSERT_EQ(rec.boxes.size(), 1u);
  EXPECT_NEAR(rec.boxes[0].objectRayOrigin[0], 0.5f, kTol);
  EXPECT_NEAR(rec.boxes[0].objectRayDirection[2], 0.5f, kTol);
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(12.5f, 1, 0, 0, 0, 1), rec).hit);
}

}  // namespace
}  // namespace vkrt::accel::test
