// Closest hits and their built-ins: t, instance/geometry/primitive indices, barycentrics, transforms, masks.
#include <algorithm>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

TEST(AccelTraversal, ClosestOfStackedQuadsWithIndicesAndBarycentrics) {
  // Quads at z = 7, 3, 5 (primitives 0-1, 2-3, 4-5): the closest along +z is the one at 3.
  auto tlas = sceneOf({quads({7, 3, 5})});
  const double v0[2] = {-1, -1}, v1[2] = {1, -1}, v2[2] = {1, 1}, v3[2] = {-1, 1};
  {
    // (0.3, -0.4) lies below the diagonal y = x: the quad's first triangle (v0, v1, v2).
    Traced r = traceOnce(*tlas, rayUp(0, 0.3f, -0.4f));
    ASSERT_TRUE(r.hit);
    EXPECT_NEAR(r.info.t, 3.0f, kTol);
    EXPECT_TRUE(r.info.triangle);
    EXPECT_EQ(r.info.instanceIndex, 0u);
    EXPECT_EQ(r.info.geometryIndex, 0u);
    EXPECT_EQ(r.info.primitiveIndex, 2u);
    const double p[2] = {0.3, -0.4};
    auto b = barycentrics2d(v0, v1, v2, p);
    EXPECT_NEAR(r.info.barycentrics[0], b[0], kTol);
    EXPECT_NEAR(r.info.barycentrics[1], b[1], kTol);
  }
  {
    // (-0.5, 0.6) lies above it: the second triangle (v0, v2, v3).
    Traced r = traceOnce(*tlas, rayUp(0, -0.5f, 0.6f));
    ASSERT_TRUE(r.hit);
    EXPECT_EQ(r.info.primitiveIndex, 3u);
    const double p[2] = {-0.5, 0.6};
    auto b = barycentrics2d(v0, v2, v3, p);
    EXPECT_NEAR(r.info.barycentrics[0], b[0], kTol);
    EXPECT_NEAR(r.info.barycentrics[1], b[1], kTol);
  }
  // From above, going down: the closest is the one at 7.
  Traced r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 10, 0, 0, -1));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 3.0f, kTol);
  EXPECT_EQ(r.info.primitiveIndex, 0u);
  // Beside the quads: a miss.
  EXPECT_FALSE(traceOnce(*tlas, rayUp(0, 1.5f, 0)).hit);
}

TEST(AccelTraversal, TIsInUnitsOfTheUnnormalizedDirection) {
  auto tlas = sceneOf({quad(5)});
  Traced r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 2));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 2.5f, kTol);
  r = traceOnce(*tlas, rayFrom(0.3f, -0.4f, 1, 0, 0, 0.5f));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 8.0f, kTol);
}

TEST(AccelTraversal, TriangleCandidatesNeedTMinBelowTBelowTMax) {
  // "tmin < t < tmax" for triangles: both ends excluded. The quad at 3 lies on each end of the interval in turn,
  // a margin beyond what any Embree kernel's rounding of its t can cross (tests/hit_distance.hpp): exactly at an
  // end, the AVX2 kernels compute t = 2.9999998 and count it inside, the AVX-512 ones 3.0 and do not.
  auto tlas = sceneOf({quads({3, 5})});
  const float margin = boundaryMargin(3.0f);
  Ray r = rayUp();
  r.tMax = 3.0f - margin;  // the quad at 3 lies beyond tmax: excluded
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  r.tMax = 3.0f + margin;
  Traced t = traceOnce(*tlas, r);
  ASSERT_TRUE(t.hit);
  EXPECT_TRUE(nearHit(t.info.t, 3.0f)) << t.info.t;
  EXPECT_LT(t.info.t, r.tMax);
  r.tMin = 3.0f + margin;  // the quad at 3 lies before tmin: excluded, so the next one is hit
  r.tMax = 100;
  t = traceOnce(*tlas, r);
  ASSERT_TRUE(t.hit);
  EXPECT_TRUE(nearHit(t.info.t, 5.0f)) << t.info.t;
  r.tMin = 3.0f - margin;
  t = traceOnce(*tlas, r);
  ASSERT_TRUE(t.hit);
  EXPECT_TRUE(nearHit(t.info.t, 3.0f)) << t.info.t;
  EXPECT_GT(t.info.t, r.tMin);
}

// vkrt consistent with itself on every set of Embree kernels (VKRT_EMBREE_ISA; the test command runs this once per
// set): rays whose interval ends lie exactly on, one float from, or a little beyond quads at depths that are not
// round in binary, traced closest-hit (the opaque fast path), through the any-hit shader, and as ray queries.
// Whatever t a kernel computes, the reported one lies strictly inside (tMin, tMax), the any-hit shader sees each
// quad the ray crosses once, and a ray query returns candidates nearest first, each inside the interval.
TEST(AccelTraversal, ReportedTLiesInsideTheIntervalAndCandidatesComeOnceOnEveryKernel) {
  const std::vector<float> depths = {0.7f, 1.3f, 2.9f, 3.1f, 4.7f, 6.1f};
  auto opaque = sceneOf({quads(depths)});
  auto anyHit = sceneOf({quads(depths, 0)});
  size_t hits = 0;
  for (uint32_t k = 0; k < 400; ++k) {
    // Points off the quads' diagonal (where two triangles meet), spread over the quad.
    const float x = -0.9f + 1.8f * float(k % 20) / 19.0f, y = -0.85f + 1.7f * float(k / 20) / 19.0f;
    if (std::fabs(x - y) < 0.02f) continue;
    const float a = depths[k % depths.size()], b = depths[(k / 7) % depths.size()];
    const float ends[][2] = {{a, b},
                             {0, a},
                             {a, 100},
                             {std::nextafter(a, 0.0f), std::nextafter(b, 100.0f)},
                             {0, std::nextafter(a, 100.0f)},
                             {std::nextafter(a, 100.0f), 100}};
    for (const auto& e : ends) {
      if (!(e[0] <= e[1])) continue;
      Ray r = rayFrom(x, y, 0, 0, 0, 1, 0, e[1], e[0]);
      // The quads strictly inside the interval by their exact depth (a depth within the rounding of an end may
      // or may not count; neither answer is wrong).
      std::vector<float> inside;
      bool ambiguous = false;
      for (float d : depths) {
        if (std::fabs(d - e[0]) <= boundaryMargin(d) || std::fabs(d - e[1]) <= boundaryMargin(d))
          ambiguous = true;
        else if (d > e[0] && d < e[1])
          inside.push_back(d);
      }
      const Traced t = traceOnce(*opaque, r);
      if (t.hit) {
        ++hits;
        EXPECT_GT(t.info.t, r.tMin) << "closest hit, interval [" << r.tMin << ", " << r.tMax << "]";
        EXPECT_LT(t.info.t, r.tMax) << "closest hit, interval [" << r.tMin << ", " << r.tMax << "]";
      }
      if (!ambiguous) {
        EXPECT_EQ(t.hit, !inside.empty());
        if (t.hit) {
          EXPECT_TRUE(nearHit(t.info.t, inside.front())) << t.info.t;
        }
      }
      Recorder ignore;
      ignore.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
      EXPECT_FALSE(traceOnce(*anyHit, r, ignore).hit);
      std::vector<float> seen;
      for (const HitInfo& h : ignore.anyHits) {
        EXPECT_GT(h.t, r.tMin) << "any-hit candidate";
        EXPECT_LT(h.t, r.tMax) << "any-hit candidate";
        seen.push_back(h.t);
      }
      std::sort(seen.begin(), seen.end());
      if (!ambiguous) {
        EXPECT_TRUE(nearHits(seen, inside)) << "each crossing once";
      }
      RayQuery q;
      queryInitialize(q, anyHit.get(), r);
      std::vector<float> returned;
      while (queryProceed(q)) {
        EXPECT_GT(q.candidate.t, r.tMin) << "ray query candidate";
        EXPECT_LT(q.candidate.t, r.tMax) << "ray query candidate";
        if (!returned.empty()) {
          EXPECT_GT(q.candidate.t, returned.back()) << "nearest first";
        }
        returned.push_back(q.candidate.t);
      }
      if (!ambiguous) {
        EXPECT_TRUE(nearHits(returned, inside)) << "ray query candidates";
      }
    }
  }
  EXPECT_GT(hits, 1000u) << "the rays meet quads";
}

TEST(AccelTraversal, InvalidRaysMiss) {
  auto tlas = sceneOf({quad(5)});
  Ray r = rayUp();
  r.tMin = 6, r.tMax = 4;  // tmin > tmax
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  r = rayUp();
  r.tMin = -1;
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  r = rayUp();
  r.origin[0] = NAN;
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  r = rayUp();
  r.tMax = NAN;
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  r = rayUp();
  r.direction[0] = INFINITY;
  EXPECT_FALSE(traceOnce(*tlas, r).hit);
  // A zero direction meets no triangle (nothing to cross), and does no harm.
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, -0.4f, 0, 0, 0, 0)).hit);
  EXPECT_TRUE(traceOnce(*tlas, rayUp()).hit);
}

TEST(AccelTraversal, InstanceBuiltInsAndIndices) {
  // Geometry 0 is empty, geometry 1 holds boxes far away, geometry 2 the quad at z = 4.
  Geometry empty;
  auto blas = makeBlas({empty, boxes({{100, 100, 100, 101, 101, 101}}), quad(4)});
  Instance a = translated(blas, 10, 0, 0);
  a.customIndex = 0xFF123456;  // 24 bits kept
  a.sbtOffset = 0xABCDEF12;
  Instance b = translated(blas, -10, 0, 0);
  b.customIndex = 7;
  b.sbtOffset = 3;
  auto tlas = makeTlas({instanceOf(nullptr), a, b});
  Traced r = traceOnce(*tlas, rayUp(0, 10.3f, -0.4f));
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.instanceIndex, 1u);
  EXPECT_EQ(r.info.customIndex, 0x123456u);
  EXPECT_EQ(r.info.sbtOffset, 0xCDEF12u);
  EXPECT_EQ(r.info.geometryIndex, 2u);
  EXPECT_EQ(r.info.primitiveIndex, 0u);
  EXPECT_NEAR(r.info.t, 4.0f, kTol);
  r = traceOnce(*tlas, rayUp(0, -9.7f, -0.4f));
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.instanceIndex, 2u);
  EXPECT_EQ(r.info.customIndex, 7u);
  EXPECT_EQ(r.info.sbtOffset, 3u);
  EXPECT_FALSE(traceOnce(*tlas, rayUp(0, 0.3f, -0.4f)).hit);
}

// Checks the hit's transforms against `in` and its object-space ray against `objectOrigin` and `objectDir`.
void expectTransforms(const HitInfo& h, const Instance& in, const float objectOrigin[3], const float objectDir[3]) {
  ASSERT_NE(h.objectToWorld, nullptr);
  ASSERT_NE(h.worldToObject, nullptr);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(h.objectToWorld[r][c], in.transform[r][c]) << r << c;
  // worldToObject * objectToWorld (as 4x4 affine matrices) is the identity.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      double v = c == 3 ? h.worldToObject[r][3] : 0;
      for (int k = 0; k < 3; ++k) v += double(h.worldToObject[r][k]) * h.objectToWorld[k][c];
      EXPECT_NEAR(v, r == c ? 1.0 : 0.0, 1e-5) << r << c;
    }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(h.objectRayOrigin[i], objectOrigin[i], 1e-4) << i;
    EXPECT_NEAR(h.objectRayDirection[i], objectDir[i], 1e-4) << i;
  }
}

TEST(AccelTraversal, RotatedInstance) {
  // 90 degrees about x: object (x, y, z) -> world (x, -z, y). The quad at object z = 5 lies in world y = -5, and a
  // ray from the origin along -y meets it at t = 5 with object direction +z.
  const auto blas = makeBlas({quad(5)});
  Instance in = instanceOf(blas);
  const float m[3][4] = {{1, 0, 0, 0}, {0, 0, -1, 0}, {0, 1, 0, 0}};
  std::copy(&m[0][0], &m[0][0] + 12, &in.transform[0][0]);
  auto tlas = makeTlas({in});
  // World (0.3, 0, 0.4) is object (0.3, 0.4, 0).
  Traced r = traceOnce(*tlas, rayFrom(0.3f, 0, 0.4f, 0, -1, 0));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  const float o[3] = {0.3f, 0.4f, 0}, d[3] = {0, 0, 1};
  expectTransforms(r.info, in, o, d);
  EXPECT_EQ(r.info.primitiveIndex, 1u);  // object (0.3, 0.4): above the diagonal
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(0.3f, 0, 0.4f, 0, 0, 1)).hit);
}

TEST(AccelTraversal, ScaledAndTranslatedInstance) {
  // Scale (2, 3, 0.5) then translate (1, 2, 3): the quad at object z = 4 is at world z = 5, spanning x in [-1, 3]
  // and y in [-1, 5]. t does not depend on the space: the direction is transformed, not normalized.
  const auto blas = makeBlas({quad(4)});
  Instance in = instanceOf(blas);
  const float m[3][4] = {{2, 0, 0, 1}, {0, 3, 0, 2}, {0, 0, 0.5f, 3}};
  std::copy(&m[0][0], &m[0][0] + 12, &in.transform[0][0]);
  auto tlas = makeTlas({in});
  Traced r = traceOnce(*tlas, rayFrom(1 + 2 * 0.3f, 2 + 3 * -0.4f, 0, 0, 0, 1));
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  const float o[3] = {0.3f, -0.4f, -6}, d[3] = {0, 0, 2};
  expectTransforms(r.info, in, o, d);
  const double v0[2] = {-1, -1}, v1[2] = {1, -1}, v2[2] = {1, 1}, p[2] = {0.3, -0.4};
  auto b = barycentrics2d(v0, v1, v2, p);
  EXPECT_NEAR(r.info.barycentrics[0], b[0], kTol);
  EXPECT_NEAR(r.info.barycentrics[1], b[1], kTol);
  EXPECT_FALSE(traceOnce(*tlas, rayFrom(3.5f, 0, 0, 0, 0, 1)).hit);  // beyond the scaled quad
  EXPECT_TRUE(traceOnce(*tlas, rayFrom(2.9f, 4.9f, 0, 0, 0, 1)).hit);
}

TEST(AccelTraversal, InstanceMaskAgainstCullMask) {
  auto blas = makeBlas({quad(5)});
  auto tlas = makeTlas({instanceOf(blas, 0, 0x0C)});
  for (uint32_t cull : {0x01u, 0x02u, 0xF3u, 0x00u, 0x100u}) {
    Ray r = rayUp();
    r.cullMask = cull;
    EXPECT_FALSE(traceOnce(*tlas, r).hit) << cull;
  }
  for (uint32_t cull : {0x04u, 0x08u, 0xFFu, 0x1FFu}) {
    Ray r = rayUp();
    r.cullMask = cull;
    EXPECT_TRUE(traceOnce(*tlas, r).hit) << cull;
  }
  // Two instances on the same ray: the mask picks which one is seen.
  auto two = makeTlas({instanceOf(blas, 0, 0x01), translated(blas, 0, 0, 2)});
  Ray r = rayUp();
  r.cullMask = 0x01;
  Traced t = traceOnce(*two, r);
  ASSERT_TRUE(t.hit);
  EXPECT_EQ(t.info.instanceIndex, 0u);
  EXPECT_NEAR(t.info.t, 5.0f, kTol);
  r.cullMask = 0x02;  // instance 1 has the default mask 0xFF
  t = traceOnce(*two, r);
  ASSERT_TRUE(t.hit);
  EXPECT_EQ(t.info.instanceIndex, 1u);
  EXPECT_NEAR(t.info.t, 7.0f, kTol);
}

TEST(AccelTraversal, EmptyStructures) {
  auto empty = makeTlas({});
  EXPECT_FALSE(traceOnce(*empty, rayUp()).hit);
  auto emptyBlas = makeBlas({});
  auto quadBlas = makeBlas({quad(5)});
  auto tlas = makeTlas({instanceOf(emptyBlas), instanceOf(quadBlas)});
  Traced r = traceOnce(*tlas, rayUp());
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.instanceIndex, 1u);
}

}  // namespace
}  // namespace vkrt::accel::test
