// Ray queries compiled and run below the Vulkan API: tests/shaders/ray_query_scene.comp against an accel::Tlas
// through exec's ray query runtime, 1,024 rays in 128 workgroups (the per-workgroup entry, over the thread pool),
// every committed value compared with the scene's geometry.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>

#include "accel/scenes.hpp"
#include "compute_harness.hpp"
#include "exec/ray_query.hpp"
#include "ray_query_scene.comp.spv.h"

namespace vkrt::testing {
namespace {

using accel::Instance;
using accel::kGeometryOpaque;
using accel::Tlas;
using accel::test::makeBlas;
using accel::test::makeTlas;
using accel::test::nearHit;
using accel::test::quad;

constexpr uint64_t kAddress = 0x5000;

// One structure at kAddress, known when the snapshot is taken; any other address resolves to nothing (the misses
// reported are counted: the resolver reports the first).
struct OneStructure : exec::TopLevelResolver {
  std::shared_ptr<const Tlas> tlas;
  std::atomic<int> misses{0};  // (workers resolve concurrently)
  std::vector<uint64_t> missedAt;
  void snapshot(Snapshot* out) override { out->structures.emplace_back(kAddress, tlas); }
  std::shared_ptr<const Tlas> resolve(uint64_t) override { return nullptr; }
  void missed(uint64_t address) override {
    ++misses;
    missedAt.push_back(address);
  }
};

struct RayIn {
  float origin[4], direction[4];
  uint32_t flags, cullMask, mode, pad;
};
struct Result {
  float hit[4];
  uint32_t ids[4], more[4];
  float rest[56];
};
static_assert(sizeof(Result) == 272);

TEST(SpirvRayQuery, ComputeShaderRunsPerWorkgroupAndCommitsTheSceneHits) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_ray_query_scene_comp)) << h.error;
  ASSERT_NE(h.shader->groupEntry, nullptr) << "a ray query shader without barriers keeps the per-workgroup entry";
  // Geometry 0: a non-opaque quad [-1, 1]^2 at z = 5; geometry 1: an opaque quad [-2, 2]^2 at z = 8. Instance custom
  // index 3.
  const auto blas = makeBlas({quad(5, 0), quad(8, kGeometryOpaque, 2)});
  Instance in = accel::test::instanceOf(blas);
  in.customIndex = 3;
  auto tlas = makeTlas({in});
  OneStructure resolver;
  resolver.tlas = tlas;
  exec::RayQueryScope scope(&resolver);
  h.rayQueries = &scope;
  h.structures[0] = kAddress;

  constexpr uint32_t n = 32;
  std::vector<RayIn> rays;
  for (uint32_t i = 0; i < n * n; ++i) {
    RayIn r{};
    const float x = (float(i % n) + 0.5f) / n * 5 - 2.5f, y = (float(i / n) + 0.5f) / n * 5 - 2.5f;
    const float o[4] = {x, y, -10, 0}, d[4] = {0, 0, 1, 100};
    std::memcpy(r.origin, o, sizeof o);
    std::memcpy(r.direction, d, sizeof d);
    r.cullMask = 0xff;
    r.mode = i % 2;  // 0: confirm, 1: ignore
    rays.push_back(r);
  }
  h.setBuffer(1, rays);
  h.zeroBuffer<Result>(2, rays.size());
  ASSERT_TRUE(h.run(n * n / 8));
  const std::vector<Result> out = h.get<Result>(2);
  int front = 0, back = 0, none = 0;
  for (uint32_t i = 0; i < n * n; ++i) {
    SCOPED_TRACE("ray " + std::to_string(i));
    const float x = rays[i].origin[0], y = rays[i].origin[1];
    const bool inNear = std::fabs(x) < 1 && std::fabs(y) < 1, inFar = std::fabs(x) < 2 && std::fabs(y) < 2;
    const Result& r = out[i];
    EXPECT_EQ(r.more[2], inNear ? 1u : 0u) << "triangle candidates";
    if (!inFar) {
      ++none;
      EXPECT_EQ(r.hit[3], 0.0f) << "no hit";
      continue;
    }
    EXPECT_EQ(r.hit[3], 1.0f) << "a triangle";
    const bool near = inNear && rays[i].mode == 0;
    (near ? front : back)++;
    // A triangle's t within the kernels' rounding (tests/hit_distance.hpp; coordinates up to 10).
    EXPECT_TRUE(nearHit(r.hit[0], near ? 15.0f : 18.0f, 10)) << r.hit[0];
    EXPECT_EQ(r.ids[0], 3u) << "custom index";
    EXPECT_EQ(r.ids[1], 0u) << "instance";
    EXPECT_EQ(r.ids[2], y > x ? 1u : 0u) << "primitive";
    EXPECT_EQ(r.ids[3], near ? 0u : 1u) << "geometry";
  }
  EXPECT_GT(front, 50);
  EXPECT_GT(back, 50);
  EXPECT_GT(none, 50);
  EXPECT_EQ(resolver.misses.load(), 0);

  // An address that is no structure: every query finds nothing, and the dispatch's first such address is reported,
  // once.
  h.structures[0] = kAddress + 64;
  ASSERT_TRUE(h.run(n * n / 8));
  for (const Result& r : h.get<Result>(2)) EXPECT_EQ(r.hit[3], 0.0f);
  EXPECT_EQ(resolver.misses.load(), 1) << "one report per dispatch";
  ASSERT_EQ(resolver.missedAt.size(), 1u);
  EXPECT_EQ(resolver.missedAt[0], kAddress + 64);
}

}  // namespace
}  // namespace vkrt::testing
