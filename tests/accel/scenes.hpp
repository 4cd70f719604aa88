// Test scenes for src/accel with expectations computed by hand: axis-aligned quads at known depths, boxes, and
// instances with known transforms. Nothing here calls into the code under test except to build and trace.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.hpp"
#include "hit_distance.hpp"

namespace vkrt::accel::test {

using ::vkrt::test::boundaryMargin;
using ::vkrt::test::hitDistanceTolerance;
using ::vkrt::test::nearHit;
using ::vkrt::test::nearHits;

// The quad [x0, x1] x [y0, y1] in the plane z = z, as two triangles (v0, v1, v2) = (x0 y0, x1 y0, x1 y1) and
// (x0 y0, x1 y1, x0 y1): both wound counterclockwise seen from +z, so (v1 - v0) x (v2 - v0) points to +z.
// `reversed` swaps v1 and v2 of both (clockwise seen from +z).
inline void addQuad(TriangleGeometry& g, float x0, float y0, float x1, float y1, float z, bool reversed = false) {
  const uint32_t base = uint32_t(g.vertices.size() / 3);
  const float v[4][3] = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  for (const auto& p : v) g.vertices.insert(g.vertices.end(), p, p + 3);
  const uint32_t tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
  for (const auto& t : tris) {
    g.indices.push_back(base + t[0]);
    g.indices.push_back(base + (reversed ? t[2] : t[1]));
    g.indices.push_back(base + (reversed ? t[1] : t[2]));
  }
}

inline Geometry quads(std::vector<float> depths, uint32_t flags = kGeometryOpaque, float half = 1.0f) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = flags;
  for (float z : depths) addQuad(g.triangles, -half, -half, half, half, z);
  return g;
}

inline Geometry quad(float z, uint32_t flags = kGeometryOpaque, float half = 1.0f) { return quads({z}, flags, half); }

inline Geometry boxes(std::vector<std::array<float, 6>> list, uint32_t flags = kGeometryOpaque) {
  Geometry g;
  g.kind = Geometry::Aabbs;
  g.aabbs.flags = flags;
  for (const auto& b : list) g.aabbs.boxes.insert(g.aabbs.boxes.end(), b.begin(), b.end());
  return g;
}

inline std::shared_ptr<Blas> makeBlas(std::vector<Geometry> geometries, const BuildOptions& options = {}) {
  std::string error;
  auto blas = Blas::build(std::move(geometries), options, &error);
  EXPECT_TRUE(blas) << error;
  return blas;
}

inline std::shared_ptr<Tlas> makeTlas(std::vector<Instance> instances, const BuildOptions& options = {}) {
  std::string error;
  auto tlas = Tlas::build(std::move(instances), options, &error);
  EXPECT_TRUE(tlas) << error;
  return tlas;
}

// An Instance does not own its Blas (accel.hpp): the helpers take a named one, which outlives the Tlas build (a
// temporary would die before it, so passing one does not compile).
template <class B>
Instance instanceOf(const std::shared_ptr<B>& blas, uint32_t flags = 0, uint32_t mask = 0xFF) {
  Instance in;
  in.blas = blas.get();
  in.flags = flags;
  in.mask = mask;
  return in;
}
template <class B>
Instance instanceOf(std::shared_ptr<B>&&, uint32_t = 0, uint32_t = 0xFF) = delete;
inline Instance instanceOf(std::nullptr_t, uint32_t flags = 0, uint32_t mask = 0xFF) {  // an inactive instance
  Instance in;
  in.flags = flags;
  in.mask = mask;
  return in;
}

template <class B>
Instance translated(const std::shared_ptr<B>& blas, float x, float y, float z) {
  Instance in = instanceOf(blas);
  in.transform[0][3] = x;
  in.transform[1][3] = y;
  in.transform[2][3] = z;
  return in;
}
template <class B>
Instance translated(std::shared_ptr<B>&&, float, float, float) = delete;

// One instance of one Blas at the identity.
inline std::shared_ptr<Tlas> sceneOf(std::vector<Geometry> geometries, uint32_t instanceFlags = 0) {
  const std::shared_ptr<const Blas> blas = makeBlas(std::move(geometries));
  return makeTlas({instanceOf(blas, instanceFlags)});
}

inline Ray rayFrom(float ox, float oy, float oz, float dx, float dy, float dz, uint32_t flags = 0, float tMax = 1000.0f,
                   float tMin = 0.0f) {
  Ray r;
  r.origin[0] = ox, r.origin[1] = oy, r.origin[2] = oz;
  r.direction[0] = dx, r.direction[1] = dy, r.direction[2] = dz;
  r.tMin = tMin;
  r.tMax = tMax;
  r.flags = flags;
  return r;
}

// A ray along +z from (x, y, 0); the default point is off the quads' diagonals.
inline Ray rayUp(uint32_t flags = 0, float x = 0.3f, float y = -0.4f) { return rayFrom(x, y, 0, 0, 0, 1, flags); }

// A HitHandler that records its calls and answers through replaceable functions (Accept, no commit by default).
struct Recorder : HitHandler {
  std::vector<HitInfo> anyHits;
  std::vector<HitInfo> boxes;  // intersect calls: the candidate's info
  std::function<AnyHitResult(const HitInfo&)> onAnyHit;
  std::function<void(ProceduralCandidate&)> onIntersect;

  AnyHitResult anyHit(const HitInfo& candidate) override {
    anyHits.push_back(candidate);
    return onAnyHit ? onAnyHit(candidate) : AnyHitResult::Accept;
  }
  void intersect(ProceduralCandidate& candidate) override {
    boxes.push_back(candidate.info());
    if (onIntersect) onIntersect(candidate);
  }
};

struct Traced {
  bool hit = false;
  HitInfo info;
};

inline Traced traceOnce(const Tlas& tlas, const Ray& ray, HitHandler& handler) {
  Traced r;
  r.hit = trace(tlas, ray, handler, &r.info);
  return r;
}

inline Traced traceOnce(const Tlas& tlas, const Ray& ray) {
  Recorder recorder;
  return traceOnce(tlas, ray, recorder);
}

// Barycentrics (weights of v1 and v2) of point p in triangle (v0, v1, v2), from the 2D coordinates (x, y): the
// solution of p = v0 + u (v1 - v0) + v (v2 - v0), by Cramer's rule.
inline std::array<double, 2> barycentrics2d(const double v0[2], const double v1[2], const double v2[2],
                                            const double p[2]) {
  const double ax = v1[0] - v0[0], ay = v1[1] - v0[1], bx = v2[0] - v0[0], by = v2[1] - v0[1];
  const double px = p[0] - v0[0], py = p[1] - v0[1];
  const double det = ax * by - ay * bx;
  return {(px * by - py * bx) / det, (ax * py - ay * px) / det};
}

constexpr float kTol = 1e-4f;

}  // namespace vkrt::accel::test
