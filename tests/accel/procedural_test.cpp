// Box primitives: when the intersection shader runs, what it sees, and its commits through ProceduralCandidate.
#include <algorithm>
#include <cmath>
#include <string>

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

// "tmin <= t <= tmax" for boxes holds when the interval is a single point: a ray starting inside a box with
// tMin == tMax meets it, and its intersection shader can report a hit at that t (the CTS's
// ray_tracing_pipeline.inside_aabbs.*.ray_end_tmax_zero.*; AccelQuery.ABoxIsACandidateAtTMinEqualTMaxFromInside
// for ray queries). Triangles still need tMin < t < tMax: none is a candidate there.
TEST(AccelProcedural, ABoxIsACandidateAtTMinEqualTMaxFromInside) {
  const std::array<float, 6> around = {-1, -1, -1, 1, 1, 1};
  auto commitAtTMin = [](Recorder& rec) {
    rec.onIntersect = [](ProceduralCandidate& c) {
      EXPECT_EQ(c.tMin(), c.tMax());
      c.commit(c.tMin(), 3, false);
    };
  };
  for (float t : {0.0f, 0.5f}) {
    SCOPED_TRACE("tMin == tMax == " + std::to_string(t));
    auto tlas = sceneOf({boxes({around})});
    Recorder rec;
    commitAtTMin(rec);
    Traced r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, t, t), rec);
    ASSERT_EQ(rec.boxes.size(), 1u) << "the intersection shader ran";
    ASSERT_TRUE(r.hit);
    EXPECT_FALSE(r.info.triangle);
    EXPECT_EQ(r.info.t, t);
    EXPECT_EQ(r.info.hitKind, 3u);
    // The same through TerminateOnFirstHit (an occlusion query).
    Recorder first;
    commitAtTMin(first);
    r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 1, kRayTerminateOnFirstHit, t, t), first);
    ASSERT_TRUE(r.hit);
    EXPECT_EQ(r.info.t, t);
  }
  // With an opaque quad through the ray's origin (its t is exactly 0 on every kernel: the origin lies in its plane)
  // and a non-opaque one: neither triangle is a candidate at tMin == tMax == 0, the box is.
  for (uint32_t flags : {uint32_t(kGeometryOpaque), 0u}) {
    SCOPED_TRACE(flags ? "opaque quad" : "non-opaque quad");
    auto mixed = sceneOf({quad(0, flags), boxes({around})});
    Recorder rec;
    commitAtTMin(rec);
    Traced r = traceOnce(*mixed, rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, 0, 0), rec);
    ASSERT_EQ(rec.boxes.size(), 1u);
    EXPECT_TRUE(rec.anyHits.empty());
    ASSERT_TRUE(r.hit);
    EXPECT_FALSE(r.info.triangle);
    EXPECT_EQ(r.info.t, 0.0f);
  }
  // A one-ulp interval [t, nextafter(t)] holds no t strictly inside it either.
  auto tlas = sceneOf({boxes({around})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) { c.commit(c.tMax(), 4, false); };
  Traced r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, std::nextafter(0.5f, 1.0f), 0.5f), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.t, std::nextafter(0.5f, 1.0f));
}

// Both ends of the interval, where boxes and triangles are both in reach: a box the ray leaves exactly at tMin (0)
// and one it enters exactly at tMax are candidates; a triangle at exactly tMin is not (nor one at or beyond tMax),
// whether or not the triangle needs the filter callback (opaque, without culling flags: Embree commits it itself).
TEST(AccelProcedural, BoxesMeetBothEndsAndTrianglesNeitherInAMixedScene) {
  // The ray (from z = 0, along +z, tMax 5) leaves box 0 at t = 0 and enters box 1 at t = 5. Boxes along a line far
  // beside it give Embree's hierarchy inner nodes, whose bounds it tests against the ray's interval (a hierarchy of
  // one leaf tests nothing before the callback).
  std::vector<std::array<float, 6>> list = {{-1, -1, -1, 1, 1, 0}, {-1, -1, 5, 1, 1, 6}};
  for (int k = 2; k < 64; ++k) list.push_back({4.0f * k, 4.0f * k, -1, 4.0f * k + 1, 4.0f * k + 1, 0});
  for (bool withTriangles : {false, true}) {
    SCOPED_TRACE(withTriangles ? "with a far quad" : "boxes only");
    std::vector<Geometry> g = {boxes(list)};
    if (withTriangles) g.push_back(quad(50));
    auto tlas = sceneOf(std::move(g));
    Ray ray = rayUp();
    ray.tMax = 5.0f;
    Recorder rec;
    EXPECT_FALSE(traceOnce(*tlas, ray, rec).hit);
    std::vector<uint32_t> seen;
    for (const HitInfo& h : rec.boxes) seen.push_back(h.primitiveIndex);
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(seen, (std::vector<uint32_t>{0, 1})) << "both boxes touching the interval's ends are candidates";
    // A hit at tMin from the box behind.
    Recorder commit;
    commit.onIntersect = [](ProceduralCandidate& c) {
      if (c.info().primitiveIndex == 0) c.commit(0.0f, 6, false);
    };
    Traced r = traceOnce(*tlas, ray, commit);
    ASSERT_TRUE(r.hit);
    EXPECT_FALSE(r.info.triangle);
    EXPECT_EQ(r.info.t, 0.0f);
    EXPECT_EQ(r.info.primitiveIndex, 0u);
  }
  for (uint32_t flags : {uint32_t(kGeometryOpaque), 0u}) {
    SCOPED_TRACE(flags ? "opaque quads" : "non-opaque quads");
    // Quads at z = 0 (the ray's origin, tMin) and z = 5, and a box far off the ray: a traversal that sees boxes.
    auto tlas = sceneOf({quads({0, 5}, flags), boxes({{10, 10, 10, 11, 11, 11}})});
    Recorder rec;
    Traced r = traceOnce(*tlas, rayUp(), rec);
    ASSERT_TRUE(r.hit) << "the quad at 5";
    EXPECT_TRUE(r.info.triangle);
    EXPECT_TRUE(nearHit(r.info.t, 5.0f)) << r.info.t;
    for (const HitInfo& h : rec.anyHits) EXPECT_GT(h.t, 0.0f) << "no candidate at tMin";
    // tMax at the quad at 5 (its t may round to either side of 5 on some kernels): a hit must lie below tMax.
    Ray ray = rayUp();
    ray.tMax = 5.0f;
    r = traceOnce(*tlas, ray, rec);
    if (r.hit) {
      EXPECT_LT(r.info.t, 5.0f);
    }
    // tMin at the quad at 5: a hit must lie above it.
    ray = rayUp();
    ray.tMin = 5.0f;
    r = traceOnce(*tlas, ray, rec);
    if (r.hit) {
      EXPECT_GT(r.info.t, 5.0f);
    }
    // tMin == tMax == 0 at the quad through the origin: nothing.
    EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, 0, 0), rec).hit);
  }
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
  const auto blas = makeBlas({boxes({kBoxA})});
  Instance in = instanceOf(blas);
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
