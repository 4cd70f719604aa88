// Ray queries (queryInitialize / queryProceed / queryConfirm / queryGenerate / queryTerminate): which candidates
// come back, in which order, and what is committed after each sequence, against scenes whose hits are known.
#include <algorithm>
#include <random>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// Runs a query to its end; `decide` answers each candidate (true: confirm a triangle / generate a box at `t` = the
// candidate's entry t). Returns the candidates' t in the order they came. (A triangle's t is compared within
// hitDistanceTolerance: Embree's kernels round it differently, tests/hit_distance.hpp.)
template <class F>
std::vector<float> drive(RayQuery& q, F decide) {
  std::vector<float> seen;
  while (queryProceed(q)) {
    seen.push_back(q.candidate.t);
    if (!decide(q)) continue;
    if (q.candidate.type == 1)
      queryConfirm(q);
    else
      queryGenerate(q, q.candidate.t);
  }
  return seen;
}

TEST(AccelQuery, NonOpaqueTrianglesComeNearestFirstAndOnce) {
  auto tlas = sceneOf({quads({5, 2, 8, 3}, 0)});
  RayQuery q;
  queryInitialize(q, tlas.get(), rayUp());
  std::vector<float> seen = drive(q, [](RayQuery&) { return false; });
  EXPECT_TRUE(nearHits(seen, {2, 3, 5, 8}));
  EXPECT_EQ(q.committed.type, 0u) << "all ignored";
  EXPECT_FALSE(queryProceed(q)) << "a finished query stays finished";

  // Confirming each: the first (nearest) stays committed and nothing behind it comes.
  queryInitialize(q, tlas.get(), rayUp());
  seen = drive(q, [](RayQuery&) { return true; });
  EXPECT_TRUE(nearHits(seen, {2}));
  EXPECT_EQ(q.committed.type, 1u);
  EXPECT_TRUE(nearHit(q.committed.t, 2.0f)) << q.committed.t;
  EXPECT_EQ(q.committed.geometry, 0u);
  const HitInfo h = queryHitInfo(q, true);
  EXPECT_TRUE(h.triangle);
  EXPECT_TRUE(nearHit(h.t, 2.0f)) << h.t;
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle) << "counterclockwise from +z, seen from below";
}

TEST(AccelQuery, OpaqueTrianglesAreCommittedByTheTraversal) {
  // Opaque at 4 and 6, non-opaque at 2, 5 and 7: only 2 comes (5 and 7 lie behind the opaque 4).
  auto tlas = sceneOf({quads({4, 6}), quads({2, 5, 7}, 0)});
  RayQuery q;
  queryInitialize(q, tlas.get(), rayUp());
  std::vector<float> seen = drive(q, [](RayQuery&) { return false; });
  EXPECT_TRUE(nearHits(seen, {2}));
  EXPECT_EQ(q.committed.type, 1u);
  EXPECT_TRUE(nearHit(q.committed.t, 4.0f)) << q.committed.t;
  EXPECT_EQ(q.committed.geometry, 0u);
  // OpaqueKHR: no candidate, the nearest committed.
  queryInitialize(q, tlas.get(), rayUp(kRayOpaque));
  EXPECT_TRUE(drive(q, [](RayQuery&) { return true; }).empty());
  EXPECT_TRUE(nearHit(q.committed.t, 2.0f)) << q.committed.t;
  // NoOpaqueKHR: everything in front of a confirmed one comes.
  queryInitialize(q, tlas.get(), rayUp(kRayNoOpaque));
  EXPECT_TRUE(nearHits(drive(q, [](RayQuery&) { return false; }), {2, 4, 5, 6, 7}));
  // CullOpaqueKHR: the opaque ones are not met at all.
  queryInitialize(q, tlas.get(), rayUp(kRayCullOpaque));
  EXPECT_TRUE(nearHits(drive(q, [](RayQuery&) { return false; }), {2, 5, 7}));
  EXPECT_EQ(q.committed.type, 0u);
  // TerminateOnFirstHitKHR: the first commit ends the query (here the opaque one, found in the first traversal).
  queryInitialize(q, tlas.get(), rayUp(kRayTerminateOnFirstHit));
  drive(q, [](RayQuery&) { return true; });
  EXPECT_EQ(q.committed.type, 1u);
  EXPECT_FALSE(queryProceed(q));
}

TEST(AccelQuery, BoxesGenerateAndTerminate) {
  // Boxes entered at 4 and 1; a non-opaque quad at 3.
  auto tlas = sceneOf({boxes({{-1, -1, 4, 1, 1, 6}, {-1, -1, 1, 1, 1, 2}}, 0), quads({3}, 0)});
  RayQuery q;
  queryInitialize(q, tlas.get(), rayUp());
  std::vector<uint32_t> types;
  std::vector<float> seen = drive(q, [&](RayQuery& r) {
    types.push_back(r.candidate.type);
    EXPECT_FALSE(r.candidate.opaque);
    return false;
  });
  EXPECT_TRUE(nearHits(seen, {1, 3, 4}));
  EXPECT_EQ(types, (std::vector<uint32_t>{2, 1, 2}));
  // Generating at 1.5 in the first box: nothing behind it comes.
  queryInitialize(q, tlas.get(), rayUp());
  ASSERT_TRUE(queryProceed(q));
  EXPECT_EQ(q.candidate.type, 2u);
  EXPECT_EQ(q.candidate.primitive, 1u);
  queryGenerate(q, 1.5f);
  EXPECT_FALSE(queryProceed(q));
  EXPECT_EQ(q.committed.type, 2u);
  EXPECT_EQ(q.committed.t, 1.5f);
  EXPECT_EQ(q.committed.primitive, 1u);
  EXPECT_FALSE(queryHitInfo(q, true).triangle);
  // A generated t outside [tMin, committed t] is not committed.
  queryInitialize(q, tlas.get(), rayUp());
  ASSERT_TRUE(queryProceed(q));
  queryGenerate(q, 2000.0f);
  EXPECT_EQ(q.committed.type, 0u);
  // Terminate: the query ends with what is committed.
  queryInitialize(q, tlas.get(), rayUp());
  ASSERT_TRUE(queryProceed(q));
  queryGenerate(q, 1.25f);
  queryTerminate(q);
  EXPECT_FALSE(queryProceed(q));
  EXPECT_EQ(q.committed.t, 1.25f);
  // SkipAABBsKHR / SkipTrianglesKHR.
  queryInitialize(q, tlas.get(), rayUp(kRaySkipAabbs));
  EXPECT_TRUE(nearHits(drive(q, [](RayQuery&) { return false; }), {3}));
  queryInitialize(q, tlas.get(), rayUp(kRaySkipTriangles));
  // (Boxes only: their entry t is vkrt's own arithmetic, exact on every kernel.)
  EXPECT_EQ(drive(q, [](RayQuery&) { return false; }), (std::vector<float>{1, 4}));
}

TEST(AccelQuery, ABoxIsACandidateAtTMinEqualTMaxFromInside) {
  auto tlas = sceneOf({boxes({{-1, -1, -1, 1, 1, 1}}, 0)});
  RayQuery q;
  queryInitialize(q, tlas.get(), rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, 0.0f, 0.0f));
  ASSERT_TRUE(queryProceed(q));
  EXPECT_EQ(q.candidate.type, 2u);
  EXPECT_EQ(q.candidate.t, 0.0f);
  queryGenerate(q, 0.0f);
  EXPECT_EQ(q.committed.type, 2u);
}

TEST(AccelQuery, NoStructureOrAnInvalidRayFindsNothing) {
  RayQuery q;
  queryInitialize(q, nullptr, rayUp());
  EXPECT_FALSE(queryProceed(q));
  EXPECT_EQ(q.committed.type, 0u);
  auto tlas = sceneOf({quads({2})});
  queryInitialize(q, tlas.get(), rayFrom(0.3f, -0.4f, 0, 0, 0, 1, 0, 1000.0f, -1.0f));  // tMin < 0
  EXPECT_FALSE(queryProceed(q));
  EXPECT_EQ(q.committed.type, 0u);
  HitInfo none = queryHitInfo(q, true);
  EXPECT_EQ(none.t, 0.0f);
}

// Against traced rays: random rays through a grid of non-opaque quads, all confirmed, commit the hit a traced ray
// (any-hit accepting everything) commits, and ignoring all returns every candidate the any-hit shader sees.
TEST(AccelQuery, AgreesWithTrace) {
  auto tlas = sceneOf({quads({1, 2.5f, 4, 7}, 0, 2.0f), boxes({{-0.5f, -0.5f, 3, 0.5f, 0.5f, 3.5f}}, 0)});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f);
  for (int i = 0; i < 200; ++i) {
    const Ray ray = rayUp(0, u(rng), u(rng));
    Recorder rec;
    rec.onIntersect = [](ProceduralCandidate& c) { c.commit(3.0f, 0, false); };
    Traced t = traceOnce(*tlas, ray, rec);
    RayQuery q;
    queryInitialize(q, tlas.get(), ray);
    drive(q, [](RayQuery& r) {
      if (r.candidate.type == 2) queryGenerate(r, 3.0f);
      return r.candidate.type == 1;
    });
    ASSERT_EQ(q.committed.type != 0, t.hit) << i;
    if (!t.hit) continue;
    EXPECT_EQ(q.committed.t, t.info.t) << i;
    EXPECT_EQ(q.committed.primitive, t.info.primitiveIndex) << i;
    EXPECT_EQ(q.committed.geometry, t.info.geometryIndex) << i;
  }
}

}  // namespace
}  // namespace vkrt::accel::test
