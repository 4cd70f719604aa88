// The cheap paths of a triangle candidate and of the committed hit (traverse.cpp), each with the case that takes it
// and the case that must not: the same crossing found by vertex index or by position, candidates at one t that are
// not one crossing, the object-space ray taken from Embree's inside an instance, and the committed hit's built-ins
// made only on request (CommittedHit, hitInfo).
#include <array>
#include <cstring>

#include "accel/scenes.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel::test {
namespace {

// Triangles far from the rays, so that a Blas is not small (kSmallBlasPrimitives): its instance is traced through
// its own Embree scene rather than flattened into the top level's.
void addFarTriangles(TriangleGeometry& g, uint32_t count) {
  for (uint32_t k = 0; k < count; ++k) {
    const uint32_t base = uint32_t(g.vertices.size() / 3);
    const float x = 100.0f + 3.0f * float(k);
    g.vertices.insert(g.vertices.end(), {x, 100, 0, x + 1, 100, 0, x, 101, 0});
    g.indices.insert(g.indices.end(), {base, base + 1, base + 2});
  }
}

Geometry triangles(std::vector<float> vertices, std::vector<uint32_t> indices, bool small) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = 0;  // not opaque: every candidate reaches the any-hit handler
  g.triangles.vertices.assign(vertices.begin(), vertices.end());
  g.triangles.indices.assign(indices.begin(), indices.end());
  if (!small) addFarTriangles(g.triangles, uint32_t(kSmallBlasPrimitives) + 4);
  return g;
}

// The square [-1, 1]^2 at z = 4 as two triangles meeting on the diagonal from (-1, -1) to (1, 1); `copies`: each
// triangle has vertices of its own (equal positions, different indices).
Geometry square(bool copies, bool small) {
  if (!copies) return triangles({-1, -1, 4, 1, -1, 4, 1, 1, 4, -1, 1, 4}, {0, 1, 2, 0, 2, 3}, small);
  return triangles({-1, -1, 4, 1, -1, 4, 1, 1, 4, -1, -1, 4, 1, 1, 4, -1, 1, 4}, {0, 1, 2, 3, 4, 5}, small);
}

// Whether traversal entered the instance's own scene (not the flattened one).
bool flattened(const Tlas& tlas) { return tlas.impl().flatScene != nullptr; }

// A ray along +z through the diagonal's point (0.25, 0.25), on the edge both triangles share.
Ray throughTheDiagonal() { return rayFrom(0.25f, 0.25f, 0, 0, 0, 1); }

TEST(AccelSameCrossing, ASharedEdgeIsOneCrossingBySharedIndexOrByCopiedPosition) {
  for (bool small : {true, false})
    for (bool copies : {false, true}) {
      SCOPED_TRACE(std::string(small ? "flattened" : "own scene") + (copies ? ", copied vertices" : ", shared"));
      auto tlas = sceneOf({square(copies, small)});
      ASSERT_EQ(flattened(*tlas), small);
      Recorder rec;
      rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };  // every candidate is offered
      EXPECT_FALSE(traceOnce(*tlas, throughTheDiagonal(), rec).hit);
      ASSERT_EQ(rec.anyHits.size(), 1u);
      EXPECT_NEAR(rec.anyHits[0].t, 4.0f, kTol);
    }
}

// Two triangles in one plane overlapping at the ray's point, sharing no vertex (position or index): the same t,
// two surfaces, both offered.
TEST(AccelSameCrossing, CandidatesAtOneTWithoutASharedVertexAreBothOffered) {
  for (bool small : {true, false}) {
    SCOPED_TRACE(small ? "flattened" : "own scene");
    auto tlas =
        sceneOf({triangles({-1, -1, 4, 2, -1, 4, -1, 2, 4, 1, 1, 4, -2, 1, 4, 1, -2, 4}, {0, 1, 2, 3, 4, 5}, small)});
    Recorder rec;
    rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
    EXPECT_FALSE(traceOnce(*tlas, rayUp(0, 0.1f, 0.2f), rec).hit);
    ASSERT_EQ(rec.anyHits.size(), 2u);
    EXPECT_EQ(rec.anyHits[0].t, rec.anyHits[1].t);
    EXPECT_NE(rec.anyHits[0].primitiveIndex, rec.anyHits[1].primitiveIndex);
  }
}

// The same square in two instances at one place: a second surface, not the same crossing, even though both of its
// triangles share the offered one's vertices (only triangles sharing some but not all vertices across instances are
// one crossing: watertight_test's closed fan).
TEST(AccelSameCrossing, TheSameTriangleInAnotherInstanceIsASecondSurface) {
  for (bool small : {true, false}) {
    SCOPED_TRACE(small ? "flattened" : "own scene");
    auto blas = makeBlas({square(false, small)});
    auto tlas = makeTlas({instanceOf(blas), instanceOf(blas)});
    Recorder rec;
    rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
    traceOnce(*tlas, rayUp(0, 0.5f, -0.25f), rec);
    ASSERT_EQ(rec.anyHits.size(), 2u);
    EXPECT_NE(rec.anyHits[0].instanceIndex, rec.anyHits[1].instanceIndex);
  }
}

bool sameBits(const float* a, const float* b, size_t n) { return std::memcmp(a, b, n * sizeof(float)) == 0; }

// The any-hit shader's view of a candidate and hitInfo() of the committed hit agree bit for bit, inside an instance
// that rotates, scales and moves its Blas (Embree's object-space ray, taken as is, and the one hitInfo() computes),
// and in a flattened one; CommittedHit carries what selects the hit group.
TEST(AccelLazyHit, TheCommittedHitsBuiltInsMatchTheAnyHitsView) {
  for (bool small : {true, false}) {
    SCOPED_TRACE(small ? "flattened" : "own scene");
    const auto blas = makeBlas({square(false, small)});
    Instance in = instanceOf(blas);
    const float m[3][4] = {{0, -2, 0, 3}, {2, 0, 0, -1}, {0, 0, 2, 4}};
    std::memcpy(in.transform, m, sizeof m);
    in.customIndex = 17;
    in.sbtOffset = 5;
    auto tlas = makeTlas({in});
    // Object space (0.3, -0.4, 0) + s (0, 0, 1) in world space.
    const float o[3] = {3.8f, -0.4f, 4}, d[3] = {0, 0, 2};
    const Ray ray = rayFrom(o[0], o[1], o[2], d[0], d[1], d[2]);
    Recorder rec;
    CommittedHit c;
    ASSERT_TRUE(trace(*tlas, ray, rec, &c));
    ASSERT_EQ(rec.anyHits.size(), 1u);
    const HitInfo& a = rec.anyHits[0];
    HitInfo h;
    hitInfo(*tlas, ray, c, &h);
    EXPECT_EQ(c.sbtOffset, 5u);
    EXPECT_TRUE(c.triangle);
    EXPECT_EQ(c.instance, 0u);
    EXPECT_EQ(h.customIndex, 17u);
    EXPECT_EQ(h.sbtOffset, 5u);
    EXPECT_EQ(h.primitiveIndex, a.primitiveIndex);
    EXPECT_EQ(h.t, a.t);
    EXPECT_EQ(h.hitKind, a.hitKind);
    EXPECT_EQ(h.barycentrics[0], a.barycentrics[0]);
    EXPECT_EQ(h.barycentrics[1], a.barycentrics[1]);
    EXPECT_TRUE(sameBits(h.objectRayOrigin, a.objectRayOrigin, 3));
    EXPECT_TRUE(sameBits(h.objectRayDirection, a.objectRayDirection, 3));
    EXPECT_NEAR(h.objectRayOrigin[0], 0.3f, kTol);
    EXPECT_NEAR(h.objectRayOrigin[1], -0.4f, kTol);
    EXPECT_NEAR(h.objectRayDirection[2], 1.0f, kTol);
    // trace() with a HitInfo is the two together.
    HitInfo whole;
    ASSERT_TRUE(trace(*tlas, ray, rec, &whole));
    EXPECT_EQ(whole.t, h.t);
    EXPECT_EQ(whole.instanceIndex, h.instanceIndex);
    EXPECT_EQ(whole.customIndex, h.customIndex);
    EXPECT_EQ(whole.sbtOffset, h.sbtOffset);
    EXPECT_EQ(whole.geometryIndex, h.geometryIndex);
    EXPECT_EQ(whole.primitiveIndex, h.primitiveIndex);
    EXPECT_EQ(whole.hitKind, h.hitKind);
    EXPECT_EQ(whole.triangle, h.triangle);
    EXPECT_TRUE(sameBits(whole.barycentrics, h.barycentrics, 2));
    EXPECT_EQ(whole.objectToWorld, h.objectToWorld);
    EXPECT_EQ(whole.worldToObject, h.worldToObject);
    EXPECT_TRUE(sameBits(whole.objectRayOrigin, h.objectRayOrigin, 3));
    EXPECT_TRUE(sameBits(whole.objectRayDirection, h.objectRayDirection, 3));
    EXPECT_EQ(whole.blas, h.blas);
  }
}

// A hit Embree commits without the filter (opaque, no culling flags) has hitKind 0 in CommittedHit, and hitInfo()
// finds its facing by the filter's rule: the same answer as the filter gives the same triangle made non-opaque.
TEST(AccelLazyHit, TheFacingOfAHitCommittedWithoutTheFilterMatchesTheFiltersAnswer) {
  for (bool small : {true, false})
    for (uint32_t instanceFlags : {0u, uint32_t(kInstanceTriangleFlipFacing)})
      for (float dz : {1.0f, -1.0f}) {
        SCOPED_TRACE(std::string(small ? "flattened" : "own scene") + " flags " + std::to_string(instanceFlags) +
                     " dz " + std::to_string(dz));
        Geometry opaque = square(false, small), noOpaque = opaque;
        opaque.triangles.flags = kGeometryOpaque;
        const Ray ray = rayFrom(0.3f, -0.4f, dz > 0 ? 0.0f : 8.0f, 0, 0, dz);
        auto plain = sceneOf({opaque}, instanceFlags);
        ASSERT_FALSE(detail::needsTriangleFilter(plain->impl().summary, 0));
        Recorder rec;
        CommittedHit c;
        ASSERT_TRUE(trace(*plain, ray, rec, &c));
        EXPECT_EQ(c.hitKind, 0u);
        HitInfo fast;
        hitInfo(*plain, ray, c, &fast);
        Traced filtered = traceOnce(*sceneOf({noOpaque}, instanceFlags), ray);
        ASSERT_TRUE(filtered.hit);
        EXPECT_EQ(fast.hitKind, filtered.info.hitKind);
        // Ng = (v1 - v0) x (v2 - v0) points to +z: a ray going down meets the front (the flag swaps it).
        const bool front = (dz < 0) != (instanceFlags != 0);
        EXPECT_EQ(fast.hitKind, front ? kHitKindFrontFacingTriangle : kHitKindBackFacingTriangle);
      }
}

// A box's committed hit: not a triangle, the intersection shader's hit kind, no barycentrics.
TEST(AccelLazyHit, ABoxHitKeepsTheShadersHitKind) {
  auto tlas = sceneOf({boxes({{-1, -1, 3, 1, 1, 5}}, kGeometryOpaque)});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) { c.commit(3.5f, 42, false); };
  CommittedHit c;
  ASSERT_TRUE(trace(*tlas, rayUp(), rec, &c));
  EXPECT_FALSE(c.triangle);
  EXPECT_EQ(c.hitKind, 42u);
  HitInfo h;
  hitInfo(*tlas, rayUp(), c, &h);
  EXPECT_FALSE(h.triangle);
  EXPECT_EQ(h.hitKind, 42u);
  EXPECT_EQ(h.t, 3.5f);
  EXPECT_EQ(h.barycentrics[0], 0.0f);
  EXPECT_EQ(h.barycentrics[1], 0.0f);
}

}  // namespace
}  // namespace vkrt::accel::test
