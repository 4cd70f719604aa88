// Inputs found by fuzz/accel_build_fuzz.cpp that made Debian's Embree 3 assert (aborting the process): rays beyond
// the coordinate range Embree traces, in world or in an instance's space, and primitives without extent (a triangle
// collapsed to a point, a box of zero size, at zero or anywhere; Embree flushes denormals to zero). The inputs are
// in fuzz/corpus/accel_build/regress-*. Expectations: what the Vulkan traversal rules give, worked out by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// A quad at z = 2 and a ray up through it: the control that the scene is hit at all.
TEST(EmbreeLimits, RayBeyondEmbreeRangeMissesInsteadOfAborting) {
  auto tlas = sceneOf({quad(2)});
  ASSERT_TRUE(traceOnce(*tlas, rayUp()).hit);
  // Finite, so Vulkan allows them; beyond 2^60 Embree cannot trace them. Both the closest-hit and the
  // terminate-on-first-hit paths (Embree's intersect and occluded).
  for (uint32_t flags : {0u, uint32_t(kRayTerminateOnFirstHit)}) {
    EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, -1e19f, 0, 0, 1, flags, 3e19f)).hit);
    EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 1e19f, flags)).hit);
    EXPECT_FALSE(traceOnce(*tlas, rayFrom(3e38f, -0.4f, 0, 0, 0, 1, flags)).hit);
  }
}

TEST(EmbreeLimits, RayBeyondEmbreeRangeInAnInstanceMisses) {
  // The instance shrinks a 3 x 3 grid of quads (18 triangles: a Blas of its own, not flattened) by 1e-10: its
  // world-to-object transform grows a ray by 1e10, so a ray from z = -1e9 is beyond 2^60 in the instance's space
  // and skips the instance.
  Geometry grid;
  grid.kind = Geometry::Triangles;
  grid.triangles.flags = kGeometryOpaque;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x)
      addQuad(grid.triangles, (x - 1.5f) * 1e10f, (y - 1.5f) * 1e10f, (x - 0.5f) * 1e10f, (y - 0.5f) * 1e10f, 2e10f);
  const auto gridBlas = makeBlas({grid});
  Instance in = instanceOf(gridBlas);
  for (int k = 0; k < 3; ++k) in.transform[k][k] = 1e-10f;
  // The same shrunk by the transform into a small Blas (2 triangles): flattened into the top level's scene in world
  // space, where the ray is within range and meets it (as Vulkan says it does).
  const auto flatBlas = makeBlas({quad(2e10f, kGeometryOpaque, 1e10f)});
  Instance flat = instanceOf(flatBlas);
  for (int k = 0; k < 3; ++k) flat.transform[k][k] = 1e-10f;
  flat.transform[0][3] = 100;  // at x in [99, 101]
  auto tlas = makeTlas({in, flat});
  Traced near = traceOnce(*tlas, rayUp());
  ASSERT_TRUE(near.hit);
  EXPECT_EQ(near.info.instanceIndex, 0u);
  EXPECT_NEAR(near.info.t, 2.0f, 1e-5f);
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, -1e9f, 0, 0, 1, 0, 1e10f)).hit);
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, -1e9f, 0, 0, 1, kRayTerminateOnFirstHit, 1e10f)).hit);
  Traced far = traceOnce(*tlas, rayFrom(100.3f, -0.4f, -1e9f, 0, 0, 1, 0, 1e10f));
  ASSERT_TRUE(far.hit);
  EXPECT_EQ(far.info.instanceIndex, 1u);
  EXPECT_NEAR(far.info.t, 1e9f + 2.0f, 1e3f);
  // Scaled by 1e-13 the transform's determinant (1e-39) is a denormal, which Embree (flushing denormals to zero)
  // cannot invert: the instance is inactive, never hit, and rays through it do not reach Embree's assertion.
  const auto tinyBlas = makeBlas({quad(2e13f, kGeometryOpaque, 1e13f)});
  Instance tiny = instanceOf(tinyBlas);
  for (int k = 0; k < 3; ++k) tiny.transform[k][k] = 1e-13f;
  auto inactive = makeTlas({tiny, tiny});
  EXPECT_FALSE(traceOnce(*inactive, rayUp()).hit);
}

// Three identity instances of a Blas whose only triangle is one point: Embree's top-level builder saw a group of
// instances without extent.
TEST(EmbreeLimits, TriangleCollapsedToAPointIsNeverHitAndKeepsTheIndices) {
  Geometry g;
  g.triangles.flags = kGeometryOpaque;
  g.triangles.vertices = {-3, -3, -3, -3, -3, -3, -3, -3, -3};
  g.triangles.indices = {0, 1, 2};
  auto point = makeBlas({g});
  auto tlas = makeTlas({instanceOf(point), instanceOf(point), instanceOf(point)});
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(-3, -3, -4, 0, 0, 1)).hit);
  // Before a real triangle: the real one keeps primitive index 1 (and 2 for the second of its quad).
  Geometry both = quad(2);
  both.triangles.vertices.insert(both.triangles.vertices.end(), {5, 5, 5});
  const uint32_t p = uint32_t(both.triangles.vertices.size() / 3 - 1);
  both.triangles.indices.insert(both.triangles.indices.begin(), {p, p, p});
  auto blas = makeBlas({both});
  auto scene = makeTlas({instanceOf(blas), translated(blas, 0, 0, 1)});
  Traced t = traceOnce(*scene, rayUp());
  ASSERT_TRUE(t.hit);
  EXPECT_FLOAT_EQ(t.info.t, 2.0f);
  EXPECT_EQ(t.info.primitiveIndex, 1u);  // (0.3, -0.4) is in the quad's first triangle, after the point
  EXPECT_EQ(t.info.instanceIndex, 0u);
}

// Zero-size boxes at the origin (a denormal widening is none to Embree) and elsewhere, in several geometries and
// instances; and a refit that collapses a triangle to a point (a full build instead).
TEST(EmbreeLimits, BoxesOfZeroSizeBuildAndStayCandidates) {
  auto blas = makeBlas({boxes({{0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}}), boxes({{0, 0, 0, 0, 0, 0}}),
                        boxes({{1e-40f, 0, 0, 2e-40f, 0, 0}}), boxes({{-1.2377e17f, 0.5f, 1, -1.2377e17f, 0.5f, 1}})});
  auto tlas = makeTlas({instanceOf(blas), instanceOf(blas)});
  // A ray through the origin meets the zero-size boxes there at t = 1 (entering and leaving every slab at once):
  // each is a candidate (tMin <= t <= tMax), so the intersection callback runs for them; a commit at t = 1 is the hit.
  Recorder r;
  r.onIntersect = [](ProceduralCandidate& c) { c.commit(1.0f, 7, false); };
  Traced t = traceOnce(*tlas, rayFrom(-1, -1, -1, 1, 1, 1), r);
  EXPECT_FALSE(r.boxes.empty());
  ASSERT_TRUE(t.hit);
  EXPECT_FLOAT_EQ(t.info.t, 1.0f);
  EXPECT_FALSE(t.info.triangle);
}

// Found by the fuzzer too: a Blas far smaller than the float resolution at its instance's position (here 1e-10
// across, translated to x = 1000, where floats are 6e-5 apart) has no extent in world space as Embree computes it,
// and two such instances made its top-level builder abort. Such an instance is left out (never hit); one whose
// extent survives the translation is hit as before.
TEST(EmbreeLimits, InstanceWithoutWorldExtentIsLeftOut) {
  Geometry tiny;
  tiny.triangles.flags = kGeometryOpaque;
  tiny.triangles.vertices = {0, 0, 1e-10f, 1e-10f, 0, 1e-10f, 0, 1e-10f, 1e-10f};
  tiny.triangles.indices = {0, 1, 2};
  auto blas = makeBlas({tiny});
  auto tlas = makeTlas({translated(blas, 1000, 0, 0), translated(blas, 1000, 0, 0), translated(blas, 0, 0, 0)});
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(1000, 0, -1, 0, 0, 1)).hit);
  Traced atOrigin = traceOnce(*tlas, rayFrom(2e-11f, 2e-11f, -1, 0, 0, 1));
  ASSERT_TRUE(atOrigin.hit);
  EXPECT_EQ(atOrigin.info.instanceIndex, 2u);
}

TEST(EmbreeLimits, UpdateThatCollapsesATriangleRebuilds) {
  BuildOptions o;
  o.allowUpdate = true;
  auto blas = makeBlas({quad(2)}, o);
  std::vector<Geometry> moved = blas->geometries();
  // Every vertex of the quad to one point: both triangles collapse.
  for (size_t i = 0; i < moved[0].triangles.vertices.size(); ++i) moved[0].triangles.vertices[i] = 0.5f;
  std::string error;
  auto updated = blas->update(moved, &error);
  ASSERT_TRUE(updated) << error;
  auto tlas = makeTlas({instanceOf(updated), instanceOf(updated), translated(updated, 0, 0, 0)});
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.5f, 0.5f, -1, 0, 0, 1)).hit);
  // And back: the quad is hit again.
  auto again = updated->update(blas->geometries(), &error);
  ASSERT_TRUE(again) << error;
  EXPECT_TRUE(traceOnce(*makeTlas({instanceOf(again), translated(again, 5, 0, 0)}), rayUp()).hit);
}

}  // namespace
}  // namespace vkrt::accel::test
