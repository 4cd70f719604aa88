// Watertightness ("Ray Traversal", Watertightness): a ray through a shared edge or a shared vertex of a closed fan
// must not fall between the triangles.
#include <embree3/rtcore.h>

#include <algorithm>
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
