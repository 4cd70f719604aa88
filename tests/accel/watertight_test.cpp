// Watertightness ("Ray Traversal", Watertightness): a ray through a shared edge or a shared vertex of a closed fan
// must not fall between the triangles.
#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// A jittered, bumpy n x n grid of quads (two triangles each, sharing their edges and vertices with the
// neighbours), and rays from below aimed at points exactly on interior shared edges (or at vertices).
struct Grid {
  static constexpr int n = 40;
  Geometry geometry;
  Grid() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-0.3f, 0.3f);
    geometry.kind = Geometry::Triangles;
    geometry.triangles.flags = kGeometryOpaque;
    auto& v = geometry.triangles.vertices;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) v.insert(v.end(), {float(i) + u(rng), float(j) + u(rng), 5 + u(rng)});
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
        geometry.triangles.indices.insert(geometry.triangles.indices.end(), {a, b, c, a, c, d});
      }
  }
  static uint32_t id(int i, int j) { return uint32_t(i * (n + 1) + j); }
  const float* vertex(uint32_t k) const { return &geometry.triangles.vertices[3 * k]; }

  std::vector<Ray> edgeRays(int count) const {
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> w(0, 1), o(-2.5f, 2.5f);
    std::vector<Ray> rays;
    for (int k = 0; k < count; ++k) {
      const int i = 1 + int(rng() % (n - 2)), j = 1 + int(rng() % (n - 2));
      // A cell's diagonal (shared by its two triangles) or its bottom edge (shared with the cell below).
      const uint32_t a = id(i, j), c = k % 2 ? id(i + 1, j + 1) : id(i + 1, j);
      const float t = k % 10 == 0 ? 0.0f : w(rng);  // every tenth at the vertex, the centre of a closed fan
      float p[3];
      for (int m = 0; m < 3; ++m) p[m] = vertex(a)[m] + t * (vertex(c)[m] - vertex(a)[m]);
      const float origin[3] = {p[0] + o(rng), p[1] + o(rng), -10};
      rays.push_back(
          rayFrom(origin[0], origin[1], origin[2], p[0] - origin[0], p[1] - origin[1], p[2] - origin[2], 0, 10.0f));
    }
    return rays;
  }
};

TEST(AccelWatertight, RaysThroughSharedEdgesAndVerticesNeverMiss) {
  Grid grid;
  auto tlas = sceneOf({grid.geometry});
  int misses = 0;
  for (const Ray& ray : grid.edgeRays(20000)) {
    Traced r = traceOnce(*tlas, ray);
    misses += !r.hit;
    if (r.hit) {
      EXPECT_NEAR(r.info.t, 1.0f, 1e-3f);
    }
  }
  EXPECT_EQ(misses, 0);
}

// A ray through a shared edge, or through the vertex at the centre of a closed fan, meets exactly one of the
// triangles there: the any-hit shader of non-opaque geometry runs once (applications count those calls, and so
// does the CTS: misc.cullmask_*, misc.maxrtinvocations_*). Ignore makes traversal offer every candidate.
TEST(AccelWatertight, NonOpaqueRaysThroughSharedEdgesAndVerticesMeetExactlyOneTriangle) {
  Grid grid;
  grid.geometry.triangles.flags = 0;  // not opaque: every candidate goes to the any-hit handler
  for (uint32_t geometryFlags : {0u, uint32_t(kGeometryNoDuplicateAnyHit)}) {
    grid.geometry.triangles.flags = geometryFlags;
    // The grid as built, and through an instance that rotates, scales and moves it (the test runs in object space).
    const auto movedBlas = makeBlas({grid.geometry});
    Instance moved = instanceOf(movedBlas);
    const float m[3][4] = {{0, -2, 0, 3}, {2, 0, 0, -1}, {0, 0, 2, 4}};
    std::copy(&m[0][0], &m[0][0] + 12, &moved.transform[0][0]);
    for (bool instanced : {false, true}) {
      auto tlas = instanced ? makeTlas({moved}) : sceneOf({grid.geometry});
      int wrong = 0, rays = 0;
      for (Ray ray : grid.edgeRays(4000)) {
        if (instanced) {
          // The same object-space ray, in world space.
          float o[3], d[3];
          for (int r = 0; r < 3; ++r) {
            o[r] = m[r][0] * ray.origin[0] + m[r][1] * ray.origin[1] + m[r][2] * ray.origin[2] + m[r][3];
            d[r] = m[r][0] * ray.direction[0] + m[r][1] * ray.direction[1] + m[r][2] * ray.direction[2];
          }
          ray = rayFrom(o[0], o[1], o[2], d[0], d[1], d[2], 0, ray.tMax);
        }
        Recorder rec;
        rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
        traceOnce(*tlas, ray, rec);
        wrong += rec.anyHits.size() != 1;
        ++rays;
      }
      EXPECT_EQ(wrong, 0) << "of " << rays << " rays, instanced " << instanced << ", flags " << geometryFlags;
    }
  }
}

// The CTS's case: a closed cube (12 triangles), a ray along the diagonal through the corner where three faces
// meet, back faces culled: one front-facing triangle is hit, once.
TEST(AccelWatertight, ARayThroughACubesCornerMeetsOneFrontFace) {
  Geometry cube;
  cube.kind = Geometry::Triangles;
  auto& t = cube.triangles;
  for (int k = 0; k < 8; ++k) t.vertices.insert(t.vertices.end(), {float(k & 1), float(k >> 1 & 1), float(k >> 2 & 1)});
  // Each face as two triangles wound counterclockwise seen from outside.
  const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) t.indices.insert(t.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  auto tlas = sceneOf({cube});
  for (uint32_t flags : {0u, uint32_t(kRayCullBackFacingTriangles)}) {
    Recorder rec;
    rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
    traceOnce(*tlas, rayFrom(-0.5f, -0.5f, -0.5f, 1, 1, 1, flags, 4.0f, 0.001f), rec);
    size_t front = 0;
    for (const HitInfo& h : rec.anyHits) front += h.hitKind == kHitKindFrontFacingTriangle;
    EXPECT_EQ(front, 1u) << "ray flags " << flags;
    EXPECT_EQ(rec.anyHits.size(), flags ? 1u : 2u) << "the far corner's back faces, once, unless culled";
  }
}

// The CTS's closed fan (watertightness.closedFan2.*): n triangles around the origin in the plane z = 0, sharing
// the centre vertex and each edge with a neighbour, every triangle in a Blas of its own and an instance of its own
// (identity transforms), non-opaque with NO_DUPLICATE_ANY_HIT. The fan and the rays are computed as the CTS
// computes them (float sin and cos).
std::shared_ptr<Tlas> closedFan(uint32_t n) {
  const float pi = 3.14159265358979f, angleDiff = 2.0f * pi / float(n);
  std::vector<std::array<float, 3>> rim;
  for (uint32_t k = 0; k < n; ++k) {
    const float angle = float(k) * angleDiff - pi;
    rim.push_back({std::sin(angle), std::cos(angle), 0.0f});
  }
  std::vector<Instance> instances;
  std::vector<std::shared_ptr<Blas>> blases;  // (instances do not own them; the Tlas does)
  for (uint32_t k = 0; k < n; ++k) {
    Geometry g;
    g.kind = Geometry::Triangles;
    g.triangles.flags = kGeometryNoDuplicateAnyHit;
    const auto& b = rim[k];
    const auto& c = rim[(k + 1) % n];
    g.triangles.vertices = {0, 0, 0, b[0], b[1], b[2], c[0], c[1], c[2]};
    g.triangles.indices = {0, 1, 2};
    blases.push_back(makeBlas({g}));
    instances.push_back(instanceOf(blases.back()));
  }
  return makeTlas(instances);
}

// The CTS's ray r of the fan of n: from (0, 0, -1) over [0.01, 9]; ray 0 at the centre, ray r at the midpoint of
// the edge from the centre to rim vertex r - 1.
Ray fanRay(uint32_t n, uint32_t r) {
  const float pi = 3.14159265358979f, angleDiff = 2.0f * pi / float(n);
  const float angle = r == 0 ? 0.0f : angleDiff * float(r - 1) - pi;
  const float tx = r == 0 ? 0.0f : 0.5f * std::sin(angle), ty = r == 0 ? 0.0f : 0.5f * std::cos(angle);
  const float len = std::sqrt(tx * tx + ty * ty + 1.0f);
  return rayFrom(0, 0, -1, tx / len, ty / len, 1 / len, 0, 9.0f, 0.01f);
}

// Each ray crosses the fan once: one any-hit call (the CTS counts them per ray, summed over the instances since
// its Geometry index is 0 in each; the any-hit accepts), and no miss.
TEST(AccelWatertight, AClosedFanOfOneTrianglePerInstanceIsCrossedOnce) {
  for (uint32_t n : {4u, 16u, 64u, 256u, 1024u}) {
    auto tlas = closedFan(n);
    for (uint32_t r = 0; r <= n; ++r) {
      Recorder rec;
      const Traced t = traceOnce(*tlas, fanRay(n, r), rec);
      EXPECT_TRUE(t.hit) << n << " triangles, ray " << r;
      EXPECT_EQ(rec.anyHits.size(), 1u) << n << " triangles, ray " << r;
    }
  }
}

// The same through a ray query that ignores every candidate: one candidate per ray.
TEST(AccelWatertight, ARayQueryThroughAClosedFanOfOneTrianglePerInstanceGetsOneCandidate) {
  for (uint32_t n : {4u, 64u, 1024u}) {
    auto tlas = closedFan(n);
    for (uint32_t r = 0; r <= n; ++r) {
      RayQuery q;
      queryInitialize(q, tlas.get(), fanRay(n, r));
      int candidates = 0;
      while (queryProceed(q)) ++candidates;
      EXPECT_EQ(candidates, 1) << n << " triangles, ray " << r;
    }
  }
}

// The premise: Embree's fast (not robust) triangle test lets some of these rays through the cracks. This is why
// vkrt builds its scenes robust (src/accel/blas.cpp); if it stops holding, the test above tests less.
TEST(AccelWatertight, EmbreesFastPathWouldMissSomeOfTheseRays) {
  Grid grid;
  RTCDevice device = rtcNewDevice("verbose=0");
  ASSERT_NE(device, nullptr);
  RTCScene scene = rtcNewScene(device);
  RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const auto& t = grid.geometry.triangles;
  auto* v = static_cast<float*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, t.vertices.size() / 3));
  std::copy(t.vertices.begin(), t.vertices.end(), v);
  auto* ix = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, t.indices.size() / 3));
  std::copy(t.indices.begin(), t.indices.end(), ix);
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  int misses = 0;
  for (const Ray& ray : grid.edgeRays(20000)) {
    RTCRayHit rh{};
    rh.ray.org_x = ray.origin[0], rh.ray.org_y = ray.origin[1], rh.ray.org_z = ray.origin[2];
    rh.ray.dir_x = ray.direction[0], rh.ray.dir_y = ray.direction[1], rh.ray.dir_z = ray.direction[2];
    rh.ray.tfar = ray.tMax;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    misses += rh.hit.geomID == RTC_INVALID_GEOMETRY_ID;
  }
  rtcReleaseScene(scene);
  rtcReleaseDevice(device);
  EXPECT_GT(misses, 0);
}

}  // namespace
}  // namespace vkrt::accel::test
