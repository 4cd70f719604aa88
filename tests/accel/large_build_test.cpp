// Builds large enough that their copies into Embree's buffers and their instance geometries are made in chunks on
// Embree's build threads (src/accel: parallelChunks; from 2^16 vertices or triangles, in chunks of at most 32,768,
// and from 4,096 instances, in chunks of at most 1,024): every primitive and instance keeps its index and is hit
// where it lies, on both sides of every chunk boundary, and triangles collapsed to a point are never hit. (A copy
// that drops one triangle or one vertex a chunk fails the first test; an instance geometry under the wrong index,
// the second.)
#include <gtest/gtest.h>

#include <set>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

constexpr uint32_t kSide = 300;  // quads a side: 180,000 triangles, 90,601 vertices

// A kSide x kSide grid of unit quads in the plane z; quad q = y * kSide + x covers [x, x+1] x [y, y+1] and holds
// triangles 2q (below its diagonal) and 2q+1 (above). Triangles in `collapsed` become the point (-5, -5, z).
Geometry grid(float z, const std::set<uint32_t>& collapsed) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  auto& v = g.triangles.vertices;
  for (uint32_t y = 0; y <= kSide; ++y)
    for (uint32_t x = 0; x <= kSide; ++x) v.insert(v.end(), {float(x), float(y), z});
  const uint32_t point = uint32_t(v.size() / 3);
  v.insert(v.end(), {-5.0f, -5.0f, z});
  auto& ix = g.triangles.indices;
  for (uint32_t y = 0; y < kSide; ++y)
    for (uint32_t x = 0; x < kSide; ++x) {
      const uint32_t a = y * (kSide + 1) + x, b = a + 1, c = b + kSide + 1, d = a + kSide + 1;
      ix.insert(ix.end(), {a, b, c, a, c, d});
    }
  for (uint32_t p : collapsed)
    for (int k = 0; k < 3; ++k) ix[3 * p + k] = point;
  return g;
}

// A ray up through the inside of triangle p.
Ray rayThrough(uint32_t p) {
  const uint32_t q = p / 2;
  const float x = float(q % kSide), y = float(q / kSide);
  return p % 2 ? rayFrom(x + 0.25f, y + 0.75f, 0, 0, 0, 1) : rayFrom(x + 0.75f, y + 0.25f, 0, 0, 0, 1);
}

TEST(LargeBuilds, EveryTriangleKeepsItsIndexAndCollapsedOnesAreNeverHit) {
  std::set<uint32_t> collapsed = {0, 32767, 32768, 65535, 65536, 179999};
  for (uint32_t p = 5; p < 2 * kSide * kSide; p += 997) collapsed.insert(p);
  std::set<uint32_t> probes(collapsed);
  for (uint32_t p : collapsed) {
    if (p > 0) probes.insert(p - 1);
    if (p + 1 < 2 * kSide * kSide) probes.insert(p + 1);
  }
  for (uint32_t p = 0; p < 2 * kSide * kSide; p += 13) probes.insert(p);

  BuildOptions options;
  options.allowUpdate = true;
  auto blas = makeBlas({grid(2, collapsed)}, options);
  ASSERT_TRUE(blas);
  EXPECT_EQ(blas->primitiveCount(), 2ull * kSide * kSide);
  auto tlas = makeTlas({instanceOf(blas)});
  ASSERT_TRUE(tlas);
  auto check = [&](const Tlas& scene, float z) {
    size_t wrong = 0;
    for (uint32_t p : probes) {
      const Traced t = traceOnce(scene, rayThrough(p));
      const bool ok = collapsed.count(p) ? !t.hit : t.hit && t.info.primitiveIndex == p && nearHit(t.info.t, z, kSide);
      if (!ok && ++wrong <= 5)
        ADD_FAILURE() << "triangle " << p << (collapsed.count(p) ? " (collapsed)" : "") << ": hit " << t.hit
                      << " primitive " << t.info.primitiveIndex << " t " << t.info.t;
    }
    EXPECT_EQ(wrong, 0u) << "of " << probes.size() << " rays";
  };
  check(*tlas, 2.0f);
  // An update of the same topology (a refit: the vertices are copied into Embree's buffer in chunks too).
  std::string error;
  auto moved = blas->update({grid(3, collapsed)}, &error);
  ASSERT_TRUE(moved) << error;
  check(*makeTlas({instanceOf(moved)}), 3.0f);
  check(*tlas, 2.0f);  // the original is unchanged
}

TEST(LargeBuilds, ThousandsOfInstancesKeepTheirIndicesMasksAndCustomIndices) {
  constexpr uint32_t kInstances = 5000, kRow = 80;
  auto blas = makeBlas({quad(0, kGeometryOpaque, 0.5f)});
  ASSERT_TRUE(blas);
  std::vector<Instance> instances;
  for (uint32_t k = 0; k < kInstances; ++k) {
    Instance in = translated(blas, 2.0f * float(k % kRow), 2.0f * float(k / kRow), 2.0f);
    if (k % 13 == 4) in.blas = nullptr;
    in.customIndex = (k * 7919u) & 0xFFFFFF;
    in.mask = k % 11 == 3 ? 0 : 0xFF;
    instances.push_back(in);
  }
  auto tlas = makeTlas(instances);
  ASSERT_TRUE(tlas);
  size_t wrong = 0;
  for (uint32_t k = 0; k < kInstances; ++k) {
    const Traced t =
        traceOnce(*tlas, rayFrom(2.0f * float(k % kRow) + 0.1f, 2.0f * float(k / kRow) - 0.2f, 0, 0, 0, 1));
    const bool never = k % 13 == 4 || k % 11 == 3;
    const bool ok = never ? !t.hit
                          : t.hit && t.info.instanceIndex == k && t.info.customIndex == ((k * 7919u) & 0xFFFFFF) &&
                                nearHit(t.info.t, 2.0f, 2.0f * kRow);
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "instance " << k << (never ? " (never hit)" : "") << ": hit " << t.hit << " instance "
                    << t.info.instanceIndex << " custom " << t.info.customIndex << " t " << t.info.t;
  }
  EXPECT_EQ(wrong, 0u);
}

}  // namespace
}  // namespace vkrt::accel::test
