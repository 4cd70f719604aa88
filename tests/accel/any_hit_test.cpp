// The any-hit shader's decisions (Accept, Ignore, AcceptAndTerminate), what it sees, and
// VK_GEOMETRY_NO_DUPLICATE_ANY_HIT_INVOCATION_BIT_KHR on a scene where spatial splits would duplicate references.
#include <embree3/rtcore.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// Non-opaque quads at 2, 4, 6, 8 (primitives 0-1, 2-3, 4-5, 6-7); the ray meets each quad's first triangle.
std::shared_ptr<Tlas> layers() { return sceneOf({quads({8, 2, 6, 4}, 0)}); }
constexpr float kDepthOfQuad[4] = {8, 2, 6, 4};

TEST(AccelAnyHit, IgnoreEverythingSeesEachCandidateOnceAndMisses) {
  auto tlas = layers();
  Recorder rec;
  rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
  EXPECT_FALSE(traceOnce(*tlas, rayUp(), rec).hit);
  ASSERT_EQ(rec.anyHits.size(), 4u);
  std::set<uint32_t> primitives;
  const double v0[2] = {-1, -1}, v1[2] = {1, -1}, v2[2] = {1, 1}, p[2] = {0.3, -0.4};
  const auto b = barycentrics2d(v0, v1, v2, p);
  for (const HitInfo& h : rec.anyHits) {
    primitives.insert(h.primitiveIndex);
    ASSERT_EQ(h.primitiveIndex % 2, 0u);
    EXPECT_NEAR(h.t, kDepthOfQuad[h.primitiveIndex / 2], kTol);
    EXPECT_TRUE(h.triangle);
    EXPECT_EQ(h.hitKind, kHitKindBackFacingTriangle);
    EXPECT_NEAR(h.barycentrics[0], b[0], kTol);
    EXPECT_NEAR(h.barycentrics[1], b[1], kTol);
    EXPECT_EQ(h.instanceIndex, 0u);
    EXPECT_EQ(h.geometryIndex, 0u);
    ASSERT_NE(h.objectToWorld, nullptr);
    EXPECT_NEAR(h.objectRayOrigin[0], 0.3f, kTol);
    EXPECT_NEAR(h.objectRayDirection[2], 1.0f, kTol);
  }
  EXPECT_EQ(primitives.size(), 4u);
}

TEST(AccelAnyHit, AcceptEverythingCommitsTheClosest) {
  auto tlas = layers();
  Recorder rec;
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 2.0f, kTol);
  EXPECT_EQ(r.info.primitiveIndex, 2u);
  EXPECT_EQ(r.info.hitKind, kHitKindBackFacingTriangle);
  // Every candidate it was asked about lay before the closest committed hit of its moment, so the closest one
  // was asked about, and nothing was asked twice.
  ASSERT_GE(rec.anyHits.size(), 1u);
  ASSERT_LE(rec.anyHits.size(), 4u);
  std::set<uint32_t> seen;
  for (const HitInfo& h : rec.anyHits) EXPECT_TRUE(seen.insert(h.primitiveIndex).second);
  EXPECT_TRUE(seen.count(2));
}

TEST(AccelAnyHit, AcceptOnlyOneLayer) {
  auto tlas = layers();
  Recorder rec;
  rec.onAnyHit = [](const HitInfo& h) {
    return std::abs(h.t - 6) < kTol ? AnyHitResult::Accept : AnyHitResult::Ignore;
  };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 6.0f, kTol);
  EXPECT_EQ(r.info.primitiveIndex, 4u);
  // The layers before it were all asked (and ignored); the one behind it may or may not have been.
  std::set<uint32_t> seen;
  for (const HitInfo& h : rec.anyHits) seen.insert(h.primitiveIndex);
  EXPECT_TRUE(seen.count(2) && seen.count(6) && seen.count(4));
}

TEST(AccelAnyHit, AcceptAndTerminateEndsTheTraversal) {
  auto tlas = layers();
  Recorder rec;
  rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::AcceptAndTerminate; };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(rec.anyHits.size(), 1u);
  EXPECT_EQ(r.info.t, rec.anyHits[0].t);
  EXPECT_EQ(r.info.primitiveIndex, rec.anyHits[0].primitiveIndex);
  EXPECT_EQ(r.info.hitKind, kHitKindBackFacingTriangle);
  EXPECT_EQ(r.info.barycentrics[0], rec.anyHits[0].barycentrics[0]);
  // Terminating on the second candidate: two calls, the second one's hit.
  Recorder second;
  second.onAnyHit = [&](const HitInfo&) {
    return second.anyHits.size() == 2 ? AnyHitResult::AcceptAndTerminate : AnyHitResult::Ignore;
  };
  r = traceOnce(*tlas, rayUp(), second);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(second.anyHits.size(), 2u);
  EXPECT_EQ(r.info.primitiveIndex, second.anyHits[1].primitiveIndex);
  // Across instances: terminating inside the first instance met stops the second one too.
  auto blas = makeBlas({quad(3, 0)});
  auto two = makeTlas({instanceOf(blas), translated(blas, 0, 0, 2)});
  Recorder across;
  across.onAnyHit = [](const HitInfo&) { return AnyHitResult::AcceptAndTerminate; };
  r = traceOnce(*two, rayUp(), across);
  ASSERT_TRUE(r.hit);
  ASSERT_EQ(across.anyHits.size(), 1u);
  EXPECT_EQ(r.info.instanceIndex, across.anyHits[0].instanceIndex);
}

TEST(AccelAnyHit, OpaqueHitsCommitWithoutTheShader) {
  // Non-opaque at 3 and 7 around an opaque quad at 5: Ignore leaves the opaque one; Accept the closest.
  auto tlas = sceneOf({quad(5, kGeometryOpaque), quads({3, 7}, 0)});
  Recorder ignore;
  ignore.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
  Traced r = traceOnce(*tlas, rayUp(), ignore);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 5.0f, kTol);
  EXPECT_EQ(r.info.geometryIndex, 0u);
  for (const HitInfo& h : ignore.anyHits) EXPECT_EQ(h.geometryIndex, 1u);
  Recorder accept;
  r = traceOnce(*tlas, rayUp(), accept);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.info.t, 3.0f, kTol);
  EXPECT_EQ(r.info.geometryIndex, 1u);
}

// A dense tangle of long, thin triangles between random points of the unit cube: the kind of scene where Embree's
// spatial-split builder (quality HIGH without the robust flag) puts one triangle into several leaves, and a ray
// crossing the cube slantwise enters more than one of them.
Geometry slivers(uint32_t flags, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = flags;
  for (int i = 0; i < count; ++i) {
    const float a[3] = {u(rng), u(rng), u(rng)}, b[3] = {u(rng), u(rng), u(rng)};
    const float w = 0.01f;
    const float v[3][3] = {{a[0], a[1], a[2]}, {b[0], b[1], b[2]}, {b[0] + w, b[1] - w, b[2] + w}};
    for (const auto& p : v) g.triangles.vertices.insert(g.triangles.vertices.end(), p, p + 3);
    for (uint32_t k = 0; k < 3; ++k) g.triangles.indices.push_back(uint32_t(3 * i) + k);
  }
  return g;
}

// Rays across the cube along +x, slightly slanted.
Ray sliverRay(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0, 1);
  const float y = u(rng), z = u(rng), dy = 0.6f * (u(rng) - 0.5f), dz = 0.6f * (u(rng) - 0.5f);
  return rayFrom(-1, y, z, 1, dy, dz);
}

// Calls per (ray, primitive) of an Embree filter, for the premise test below.
struct DuplicateCounter {
  RTCIntersectContext context;
  std::map<unsigned, int> calls;
};

void countAndReject(const RTCFilterFunctionNArguments* args) {
  auto* counter = reinterpret_cast<DuplicateCounter*>(args->context);
  counter->calls[RTCHitN_primID(args->hit, args->N, 0)]++;
  args->valid[0] = 0;
}

// The premise: raw Embree with spatial splits (HIGH, not robust) reports some of these slivers more than once per
// ray. (If this stops holding, the next test no longer tests anything.)
TEST(AccelNoDuplicateAnyHit, SpatialSplitsWouldDuplicateInThisScene) {
  Geometry g = slivers(0, 4000, 7);
  RTCDevice device = rtcNewDevice("verbose=0");
  ASSERT_NE(device, nullptr);
  RTCScene scene = rtcNewScene(device);
  rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12,
                                                        g.triangles.vertices.size() / 3));
  std::copy(g.triangles.vertices.begin(), g.triangles.vertices.end(), v);
  auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12,
                                                            g.triangles.indices.size() / 3));
  std::copy(g.triangles.indices.begin(), g.triangles.indices.end(), ix);
  rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_HIGH);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(scene);
  int duplicated = 0;
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    DuplicateCounter counter;
    rtcInitIntersectContext(&counter.context);
    counter.context.filter = countAndReject;
    const Ray ray = sliverRay(rng);
    RTCRayHit rh{};
    rh.ray.org_x = ray.origin[0], rh.ray.org_y = ray.origin[1], rh.ray.org_z = ray.origin[2];
    rh.ray.dir_x = ray.direction[0], rh.ray.dir_y = ray.direction[1], rh.ray.dir_z = ray.direction[2];
    rh.ray.tfar = 100;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &counter.context, &rh);
    for (const auto& [prim, n] : counter.calls) duplicated += n > 1;
  }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  EXPECT_GT(duplicated, 0);
}

// With the flag, preferFastTrace (the build option that would choose spatial splits) must still call the
// any-hit shader at most once per primitive per ray.
TEST(AccelNoDuplicateAnyHit, AtMostOneAnyHitPerPrimitivePerRay) {
  BuildOptions fastTrace;
  fastTrace.preferFastTrace = true;
  auto blas = makeBlas({slivers(kGeometryNoDuplicateAnyHit, 4000, 7)}, fastTrace);
  auto tlas = makeTlas({instanceOf(blas)}, fastTrace);
  std::mt19937 rng(3);
  size_t calls = 0;
  for (int i = 0; i < 2000; ++i) {
    Recorder rec;
    rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
    const Ray ray = sliverRay(rng);
    EXPECT_FALSE(traceOnce(*tlas, ray, rec).hit);
    std::map<uint32_t, int> perPrimitive;
    for (const HitInfo& h : rec.anyHits) ASSERT_EQ(++perPrimitive[h.primitiveIndex], 1) << "ray " << i;
    calls += rec.anyHits.size();
  }
  EXPECT_GT(calls, 2000u);  // the rays do meet slivers
}

}  // namespace
}  // namespace vkrt::accel::test
