// src/accel below the Vulkan API: analytic scenes (axis-aligned quads and boxes at known depths, instances with
// known transforms) traced with every ray, instance and geometry flag; expectations computed here.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <thread>
#include <vector>

#include "accel/accel.hpp"

namespace vkrt::accel {
namespace {

// A unit quad in the plane z = `z` over [x0, x0 + 1] x [y0, y0 + 1]: two triangles (0: v0 v1 v2, 1: v2 v1 v3), both
// wound so that their normal cross(v1 - v0, v2 - v0) is +z.
Geometry quad(float z, uint32_t flags, float x0 = 0, float y0 = 0) {
  Geometry g;
  g.triangles.vertices = {x0, y0, z, x0 + 1, y0, z, x0, y0 + 1, z, x0 + 1, y0 + 1, z};
  g.triangles.indices = {0, 1, 2, 2, 1, 3};
  g.triangles.flags = flags;
  return g;
}

Geometry boxes(std::vector<float> b, uint32_t flags) {
  Geometry g;
  g.kind = Geometry::Aabbs;
  g.aabbs.boxes.assign(b.begin(), b.end());
  g.aabbs.flags = flags;
  return g;
}

std::shared_ptr<const Blas> blasOf(std::vector<Geometry> gs, BuildOptions o = {}) {
  std::string error;
  auto b = Blas::build(std::move(gs), o, &error);
  EXPECT_NE(b, nullptr) << error;
  return b;
}

// An Instance does not own its Blas (accel.hpp): a named one, which outlives the Tlas build.
template <class B>
Instance instanceOf(const std::shared_ptr<B>& b, float tx = 0, float ty = 0, float tz = 0) {
  Instance in;
  in.blas = b.get();
  in.transform[0][3] = tx;
  in.transform[1][3] = ty;
  in.transform[2][3] = tz;
  return in;
}
template <class B>
Instance instanceOf(std::shared_ptr<B>&&, float = 0, float = 0, float = 0) = delete;

std::shared_ptr<const Tlas> tlasOf(std::vector<Instance> is) {
  std::string error;
  auto t = Tlas::build(std::move(is), {}, &error);
  EXPECT_NE(t, nullptr) << error;
  return t;
}

Ray rayAt(float x, float y, uint32_t flags = 0, float z = 0) {
  Ray r;
  r.origin[0] = x;
  r.origin[1] = y;
  r.origin[2] = z;
  r.direction[0] = 0;
  r.direction[1] = 0;
  r.direction[2] = 1;
  r.tMin = 0;
  r.tMax = 100;
  r.flags = flags;
  return r;
}

// Records the callbacks; answers any-hit with `anyHitAnswer`, and for boxes reports a hit at the box's entry
// along +z (the box's min z, minus the ray origin's z) with hit kind 7 + primitive index.
struct Recorder : HitHandler {
  AnyHitResult anyHitAnswer = AnyHitResult::Accept;
  bool terminateInIntersection = false;
  std::vector<HitInfo> anyHits, boxes;
  std::map<std::pair<uint32_t, uint32_t>, int> anyHitsPerPrimitive;  // (geometry, primitive) -> calls
  std::vector<std::vector<float>> boxData;                           // per geometry index, for the reports

  AnyHitResult anyHit(const HitInfo& c) override {
    anyHits.push_back(c);
    ++anyHitsPerPrimitive[{c.geometryIndex, c.primitiveIndex}];
    return anyHitAnswer;
  }
  void intersect(ProceduralCandidate& c) override {
    boxes.push_back(c.info());
    const std::vector<float>& b = boxData.at(c.info().geometryIndex);
    float t = b[c.info().primitiveIndex * 6 + 2] - c.info().objectRayOrigin[2];
    if (t >= c.tMin() && t <= c.tMax()) c.commit(t, 7 + c.info().primitiveIndex, terminateInIntersection);
  }
};

TEST(AccelTrace, ClosestTriangleWithBarycentricsIdsAndFacing) {
  const auto blas = blasOf({quad(5, kGeometryOpaque), quad(3, kGeometryOpaque)});
  auto tlas = tlasOf({instanceOf(blas)});
  Recorder rec;
  HitInfo h;
  ASSERT_TRUE(trace(*tlas, rayAt(0.25f, 0.125f), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 3.0f);
  EXPECT_EQ(h.geometryIndex, 1u);
  EXPECT_EQ(h.primitiveIndex, 0u);
  EXPECT_TRUE(h.triangle);
  // Point (0.25, 0.125) = v0 + u (v1 - v0) + v (v2 - v0) with v1 - v0 = +x, v2 - v0 = +y.
  EXPECT_FLOAT_EQ(h.barycentrics[0], 0.25f);
  EXPECT_FLOAT_EQ(h.barycentrics[1], 0.125f);
  // The normal (+z) points along the ray: back-facing.
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);
  EXPECT_TRUE(rec.anyHits.empty()) << "opaque geometry runs no any-hit";
  // The second triangle of the quad, (v2, v1, v3) with v1 = (1, 0), v2 = (0, 1), v3 = (1, 1).
  ASSERT_TRUE(trace(*tlas, rayAt(0.75f, 0.875f), rec, &h));
  EXPECT_EQ(h.primitiveIndex, 1u);
  // (0.75, 0.875) = (0, 1) + u (1, -1) + v (1, 0): u = 0.125 (weight of v1), v = 0.625 (weight of v3).
  EXPECT_FLOAT_EQ(h.barycentrics[0], 0.125f);
  EXPECT_FLOAT_EQ(h.barycentrics[1], 0.625f);
  EXPECT_FALSE(trace(*tlas, rayAt(1.5f, 0.5f), rec, &h)) << "outside the quads";
  // From the other side (origin z = 10, direction -z) the same triangles are front-facing and z = 5 is closest.
  Ray back = rayAt(0.25f, 0.125f, 0, 10);
  back.direction[2] = -1;
  ASSERT_TRUE(trace(*tlas, back, rec, &h));
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  EXPECT_EQ(h.hitKind, kHitKindFrontFacingTriangle);
}

TEST(AccelTrace, InstancesTransformsCustomIndexSbtOffsetAndMasks) {
  auto blas = blasOf({quad(5, kGeometryOpaque)});
  Instance a = instanceOf(blas, 0, 0, 0);
  a.customIndex = 0x123456;
  a.sbtOffset = 7;
  a.mask = 0x01;
  Instance b = instanceOf(blas, 0, 0, -3);  // its quad at z = 2
  b.customIndex = 42;
  b.sbtOffset = 3;
  b.mask = 0x02;
  auto tlas = tlasOf({a, b});
  Recorder rec;
  HitInfo h;
  Ray r = rayAt(0.5f, 0.25f);
  ASSERT_TRUE(trace(*tlas, r, rec, &h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_EQ(h.instanceIndex, 1u);
  EXPECT_EQ(h.customIndex, 42u);
  EXPECT_EQ(h.sbtOffset, 3u);
  EXPECT_FLOAT_EQ(h.objectRayOrigin[2], 3.0f) << "world z 0 is object z 3 in instance b";
  EXPECT_FLOAT_EQ(h.objectToWorld[2][3], -3.0f);
  EXPECT_FLOAT_EQ(h.worldToObject[2][3], 3.0f);
  // Cull mask 0x01 skips instance b (mask 0x02): instance a at t = 5.
  r.cullMask = 0x01;
  ASSERT_TRUE(trace(*tlas, r, rec, &h));
  EXPECT_EQ(h.instanceIndex, 0u);
  EXPECT_EQ(h.customIndex, 0x123456u);
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  r.cullMask = 0x04;
  EXPECT_FALSE(trace(*tlas, r, rec, &h));
}

TEST(AccelTrace, RotatedScaledAndMirroredInstances) {
  auto blas = blasOf({quad(0, kGeometryOpaque)});  // in the plane z = 0 of object space
  // world = M object: wx = 2 oz, wy = 2 oy, wz = 4 - 2 ox (a rotation about y, scaled by 2, moved along z). The
  // quad (object z = 0) stands in the plane world x = 0.
  Instance rot;
  rot.blas = blas.get();
  const float m[3][4] = {{0, 0, 2, 0}, {0, 2, 0, 0}, {-2, 0, 0, 4}};
  std::memcpy(rot.transform, m, sizeof m);
  auto tlas = tlasOf({rot});
  Recorder rec;
  HitInfo h;
  // A ray along world +x from (-1, 0.5, 3) meets world x = 0 at t = 1.
  Ray r;
  r.origin[0] = -1;
  r.origin[1] = 0.5f;
  r.origin[2] = 3;
  r.direction[0] = 1;
  r.direction[1] = 0;
  r.direction[2] = 0;
  r.tMax = 10;
  ASSERT_TRUE(trace(*tlas, r, rec, &h));
  EXPECT_NEAR(h.t, 1.0f, 1e-5f);
  // Object space: object = ((4 - wz) / 2, wy / 2, wx / 2), so the origin is (0.5, 0.25, -0.5), the direction (0, 0,
  // 0.5).
  EXPECT_NEAR(h.objectRayOrigin[0], 0.5f, 1e-5f);
  EXPECT_NEAR(h.objectRayOrigin[1], 0.25f, 1e-5f);
  EXPECT_NEAR(h.objectRayOrigin[2], -0.5f, 1e-5f);
  EXPECT_NEAR(h.objectRayDirection[2], 0.5f, 1e-5f);
  // Object direction +z along the quad's normal +z: back-facing, as in object space.
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);
  // A mirrored instance (x scaled by -1) keeps object-space facing: the object ray still runs along +z.
  Instance mirror = instanceOf(blas, 0, 0, 5);
  mirror.transform[0][0] = -1;
  auto tlas2 = tlasOf({mirror});
  ASSERT_TRUE(trace(*tlas2, rayAt(-0.5f, 0.5f), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);
  EXPECT_FLOAT_EQ(h.objectRayOrigin[0], 0.5f);
}

TEST(AccelTrace, FacingCullingAndInstanceFacingFlags) {
  auto blas = blasOf({quad(5, kGeometryOpaque)});
  Recorder rec;
  HitInfo h;
  auto plain = tlasOf({instanceOf(blas)});
  EXPECT_FALSE(trace(*plain, rayAt(0.2f, 0.2f, kRayCullBackFacingTriangles), rec, &h)) << "back-facing culled";
  ASSERT_TRUE(trace(*plain, rayAt(0.2f, 0.2f, kRayCullFrontFacingTriangles), rec, &h));
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);

  Instance flipped = instanceOf(blas);
  flipped.flags = kInstanceTriangleFlipFacing;
  auto flip = tlasOf({flipped});
  ASSERT_TRUE(trace(*flip, rayAt(0.2f, 0.2f), rec, &h));
  EXPECT_EQ(h.hitKind, kHitKindFrontFacingTriangle);
  EXPECT_FALSE(trace(*flip, rayAt(0.2f, 0.2f, kRayCullFrontFacingTriangles), rec, &h));
  EXPECT_TRUE(trace(*flip, rayAt(0.2f, 0.2f, kRayCullBackFacingTriangles), rec, &h));

  Instance noCull = instanceOf(blas);
  noCull.flags = kInstanceTriangleFacingCullDisable;
  auto disabled = tlasOf({noCull});
  ASSERT_TRUE(trace(*disabled, rayAt(0.2f, 0.2f, kRayCullBackFacingTriangles), rec, &h)) << "culling disabled";
  EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);
}

TEST(AccelTrace, AnyHitAcceptIgnoreTerminateAndOpacityFlags) {
  // Two non-opaque quads at z = 3 and z = 5, an opaque one at z = 7.
  auto blas = blasOf({quad(3, 0), quad(5, 0), quad(7, kGeometryOpaque)});
  auto tlas = tlasOf({instanceOf(blas)});
  HitInfo h;
  {
    Recorder rec;  // Accept: the closest, z = 3, with its any-hit run (others may run too, in any order)
    ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f), rec, &h));
    EXPECT_FLOAT_EQ(h.t, 3.0f);
    ASSERT_FALSE(rec.anyHits.empty());
    for (const HitInfo& c : rec.anyHits) EXPECT_NE(c.geometryIndex, 2u) << "the opaque quad runs no any-hit";
  }
  {
    Recorder rec;  // Ignore: both non-opaque quads are dropped, the opaque one at z = 7 is hit
    rec.anyHitAnswer = AnyHitResult::Ignore;
    ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f), rec, &h));
    EXPECT_FLOAT_EQ(h.t, 7.0f);
    EXPECT_EQ(rec.anyHits.size(), 2u);
  }
  {
    Recorder rec;  // Terminate: the first candidate offered is committed and traversal stops
    rec.anyHitAnswer = AnyHitResult::AcceptAndTerminate;
    ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f), rec, &h));
    ASSERT_EQ(rec.anyHits.size(), 1u);
    EXPECT_FLOAT_EQ(h.t, rec.anyHits[0].t);
  }
  {
    Recorder rec;  // the ray's Opaque flag: no any-hit at all, z = 3
    ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f, kRayOpaque), rec, &h));
    EXPECT_FLOAT_EQ(h.t, 3.0f);
    EXPECT_TRUE(rec.anyHits.empty());
  }
  {
    Recorder rec;  // NoOpaque: the opaque quad runs its any-hit too
    rec.anyHitAnswer = AnyHitResult::Ignore;
    EXPECT_FALSE(trace(*tlas, rayAt(0.2f, 0.2f, kRayNoOpaque), rec, &h));
    EXPECT_EQ(rec.anyHits.size(), 3u);
  }
  {
    Recorder rec;  // CullOpaque: only the non-opaque quads remain; CullNoOpaque: only the opaque one
    ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f, kRayCullNoOpaque), rec, &h));
    EXPECT_FLOAT_EQ(h.t, 7.0f);
    EXPECT_TRUE(rec.anyHits.empty());
    rec.anyHitAnswer = AnyHitResult::Ignore;
    EXPECT_FALSE(trace(*tlas, rayAt(0.2f, 0.2f, kRayCullOpaque), rec, &h));
    EXPECT_EQ(rec.anyHits.size(), 2u);
  }
  {
    // Instance flags: ForceOpaque makes every geometry opaque, ForceNoOpaque none.
    Instance fo = instanceOf(blas);
    fo.flags = kInstanceForceOpaque;
    Recorder rec;
    ASSERT_TRUE(trace(*tlasOf({fo}), rayAt(0.2f, 0.2f), rec, &h));
    EXPECT_TRUE(rec.anyHits.empty());
    Instance fno = instanceOf(blas);
    fno.flags = kInstanceForceNoOpaque;
    rec.anyHitAnswer = AnyHitResult::Ignore;
    EXPECT_FALSE(trace(*tlasOf({fno}), rayAt(0.2f, 0.2f), rec, &h));
    EXPECT_EQ(rec.anyHits.size(), 3u);
  }
}

TEST(AccelTrace, TerminateOnFirstHitAndSkipFlags) {
  auto blas = blasOf({quad(3, 0), quad(5, 0), boxes({0, 0, 1, 1, 1, 2}, kGeometryOpaque)});
  auto tlas = tlasOf({instanceOf(blas)});
  Recorder rec;
  rec.boxData = {{}, {}, {0, 0, 1, 1, 1, 2}};
  HitInfo h;
  ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f, kRayTerminateOnFirstHit), rec, &h));
  EXPECT_EQ(rec.anyHits.size() + rec.boxes.size(), 1u) << "one candidate accepted, then nothing more";
  rec = Recorder{};
  rec.boxData = {{}, {}, {0, 0, 1, 1, 1, 2}};
  ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f, kRaySkipAabbs), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 3.0f);
  EXPECT_TRUE(rec.boxes.empty());
  rec.anyHits.clear();
  ASSERT_TRUE(trace(*tlas, rayAt(0.2f, 0.2f, kRaySkipTriangles), rec, &h));
  EXPECT_FALSE(h.triangle);
  EXPECT_FLOAT_EQ(h.t, 1.0f);
  EXPECT_EQ(h.hitKind, 7u);
  EXPECT_TRUE(rec.anyHits.empty());
  EXPECT_FALSE(trace(*tlas, rayAt(0.2f, 0.2f, kRaySkipTriangles | kRaySkipAabbs), rec, &h));
}

TEST(AccelTrace, BoxesRunTheIntersectionHandlerAndCommitTheClosest) {
  // Two boxes on the ray (entries at z = 4 and z = 2) and one beside it.
  std::vector<float> b = {0, 0, 4, 1, 1, 5, 0, 0, 2, 1, 1, 3, 5, 5, 0, 6, 6, 1};
  const auto blas = blasOf({boxes(b, 0)});
  auto tlas = tlasOf({instanceOf(blas, 0, 0, 1)});  // moved to z + 1
  Recorder rec;
  rec.boxData = {b};
  HitInfo h;
  ASSERT_TRUE(trace(*tlas, rayAt(0.5f, 0.5f), rec, &h));
  EXPECT_FALSE(h.triangle);
  EXPECT_EQ(h.primitiveIndex, 1u);
  EXPECT_EQ(h.hitKind, 8u);
  EXPECT_FLOAT_EQ(h.t, 3.0f) << "box entry z = 2 in object space is world z = 3";
  EXPECT_LE(rec.boxes.size(), 2u) << "the box beside the ray is never offered";
  for (const HitInfo& c : rec.boxes) EXPECT_NE(c.primitiveIndex, 2u);
  // tMax bounds the boxes offered: with tMax 2.5 neither box can be entered.
  rec.boxes.clear();
  Ray r = rayAt(0.5f, 0.5f);
  r.tMax = 2.5f;
  EXPECT_FALSE(trace(*tlas, r, rec, &h));
  EXPECT_TRUE(rec.boxes.empty());
}

TEST(AccelTrace, NoDuplicateAnyHitEvenInADenseHighQualityScene) {
  // 3000 long, thin, overlapping triangles around the z axis, the kind of scene a spatial-split builder duplicates
  // references in. (Measured: Embree 3.13's high-quality builder called no filter twice for one primitive even
  // without the flag; build.cpp avoids it for flagged geometry regardless. What this test guards is that a candidate
  // reaches the handler once.)
  Geometry g;
  for (int i = 0; i < 3000; ++i) {
    float a = float(i) * 0.00209f, z = 2 + float(i % 97) * 0.05f;
    float c = std::cos(a) * 30, s = std::sin(a) * 30;
    uint32_t base = uint32_t(g.triangles.vertices.size() / 3);
    g.triangles.vertices.insert(g.triangles.vertices.end(), {-c, -s, z, c, s, z + 0.01f, -s * 0.02f, c * 0.02f, z});
    g.triangles.indices.insert(g.triangles.indices.end(), {base, base + 1, base + 2});
  }
  g.triangles.flags = kGeometryNoDuplicateAnyHit;
  BuildOptions fast;
  fast.preferFastTrace = true;
  const auto blas = blasOf({g}, fast);
  auto tlas = tlasOf({instanceOf(blas)});
  for (float x : {-0.3f, 0.0f, 0.2f}) {
    Recorder rec;
    rec.anyHitAnswer = AnyHitResult::Ignore;
    HitInfo h;
    EXPECT_FALSE(trace(*tlas, rayAt(x, 0.01f), rec, &h));
    EXPECT_FALSE(rec.anyHits.empty());
    for (auto& [prim, calls] : rec.anyHitsPerPrimitive) EXPECT_EQ(calls, 1) << "primitive " << prim.second;
  }
}

TEST(AccelTrace, InactivePrimitivesAndInstancesKeepTheOthersIndices) {
  Geometry g = quad(5, kGeometryOpaque);
  g.triangles.vertices.insert(g.triangles.vertices.end(), {NAN, 0, 3, 1, 0, 3, 0, 1, 3});
  g.triangles.indices.insert(g.triangles.indices.end(), {4, 5, 6});
  std::vector<float> b = {NAN, 0, 0, 1, 1, 1, 0, 0, 8, 1, 1, 9};
  auto blas = blasOf({g, boxes(b, kGeometryOpaque)});
  Instance none;  // no Blas: inactive
  auto tlas = tlasOf({none, instanceOf(blas)});
  Recorder rec;
  rec.boxData = {{}, b};
  HitInfo h;
  ASSERT_TRUE(trace(*tlas, rayAt(0.25f, 0.25f), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 5.0f) << "the NaN triangle at z = 3 is inactive";
  EXPECT_EQ(h.instanceIndex, 1u);
  for (const HitInfo& c : rec.boxes) EXPECT_EQ(c.primitiveIndex, 1u) << "the NaN box is never offered";
  ASSERT_TRUE(trace(*tlas, rayAt(0.25f, 0.25f, kRaySkipTriangles), rec, &h));
  EXPECT_EQ(h.primitiveIndex, 1u);
  EXPECT_EQ(h.hitKind, 8u);
}

// (Out-of-range indices: build_test.cpp's OutOfRangeIndicesAreNeverHit; the runtime refuses them at maxVertex.)
TEST(AccelBuild, UpdateLeavesTheOriginal) {
  std::string error;
  auto original = blasOf({quad(5, kGeometryOpaque)});
  auto moved = original->update({quad(2, kGeometryOpaque)}, &error);
  ASSERT_NE(moved, nullptr) << error;
  Recorder rec;
  HitInfo h;
  ASSERT_TRUE(trace(*tlasOf({instanceOf(original)}), rayAt(0.5f, 0.2f), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  ASSERT_TRUE(trace(*tlasOf({instanceOf(moved)}), rayAt(0.5f, 0.2f), rec, &h));
  EXPECT_FLOAT_EQ(h.t, 2.0f);
}

TEST(AccelSerialize, RoundTripTracesTheSameAndDamageIsRefused) {
  std::vector<float> b = {0, 0, 8, 1, 1, 9};
  auto blas = blasOf({quad(5, kGeometryOpaque), boxes(b, 0)});
  Instance in = instanceOf(blas, 0.5f, 0, 1);
  in.customIndex = 9;
  in.flags = kInstanceTriangleFlipFacing;
  auto tlas = tlasOf({in});
  std::vector<uint8_t> bb = serialize(*blas);
  std::vector<const Blas*> refs;
  std::vector<uint8_t> tb = serialize(*tlas, &refs);
  ASSERT_EQ(refs.size(), 1u);
  EXPECT_EQ(refs[0], blas.get());
  std::string error;
  auto blas2 = deserializeBlas(bb.data(), bb.size(), &error);
  ASSERT_NE(blas2, nullptr) << error;
  auto tlas2 = deserializeTlas(tb.data(), tb.size(), {blas2}, &error);
  ASSERT_NE(tlas2, nullptr) << error;
  EXPECT_EQ(serialize(*blas2), bb) << "deserialized and serialized again: the same bytes";
  for (uint32_t flags : {0u, uint32_t(kRaySkipTriangles)}) {
    Recorder r1, r2;
    r1.boxData = r2.boxData = {{}, b};
    HitInfo h1, h2;
    ASSERT_TRUE(trace(*tlas, rayAt(0.7f, 0.5f, flags), r1, &h1));
    ASSERT_TRUE(trace(*tlas2, rayAt(0.7f, 0.5f, flags), r2, &h2));
    EXPECT_EQ(h1.t, h2.t);
    EXPECT_EQ(h1.hitKind, h2.hitKind);
    EXPECT_EQ(h1.customIndex, h2.customIndex);
    EXPECT_EQ(h1.primitiveIndex, h2.primitiveIndex);
  }
  // Truncations and flipped bytes anywhere are refused or still decode to a valid structure, never crash.
  for (size_t n = 0; n < bb.size(); n += 7) EXPECT_EQ(deserializeBlas(bb.data(), n, &error), nullptr) << n;
  for (size_t i = 0; i < bb.size(); ++i) {
    std::vector<uint8_t> d = bb;
    d[i] ^= 0x5a;
    deserializeBlas(d.data(), d.size(), &error);
  }
  EXPECT_EQ(deserializeTlas(tb.data(), tb.size(), {}, &error), nullptr) << "a reference past the list";
  EXPECT_EQ(deserializeTlas(bb.data(), bb.size(), {blas2}, &error), nullptr) << "bottom-level data as top-level";
}

TEST(AccelTrace, ManyThreadsGetTheSameAnswers) {
  std::vector<Geometry> gs;
  for (int i = 0; i < 50; ++i)
    gs.push_back(
        quad(float(2 + i % 7), i % 3 ? uint32_t(kGeometryOpaque) : 0u, float(i % 10) * 0.5f, float(i / 10) * 0.5f));
  const auto first = blasOf(gs), second = blasOf(gs);
  auto tlas = tlasOf({instanceOf(first), instanceOf(second, 0.25f, 0.25f, 0.5f)});
  auto run = [&](std::vector<float>* out) {
    Recorder rec;
    for (int y = 0; y < 60; ++y)
      for (int x = 0; x < 60; ++x) {
        HitInfo h;
        out->push_back(trace(*tlas, rayAt(float(x) * 0.1f, float(y) * 0.05f), rec, &h) ? h.t * 1000 + h.primitiveIndex
                                                                                       : -1);
      }
  };
  std::vector<float> one;
  run(&one);
  std::vector<std::vector<float>> many(8);
  std::vector<std::thread> threads;
  for (auto& m : many) threads.emplace_back(run, &m);
  for (auto& t : threads) t.join();
  for (auto& m : many) EXPECT_EQ(m, one);
}

}  // namespace
}  // namespace vkrt::accel
