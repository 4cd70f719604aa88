// Packets (accel::tracePacket): up to 16 rays through one Embree packet query where each ray meets nothing that calls
// back (accel::packetTraceable). Each lane must commit exactly what trace() commits for its ray alone: the same hit
// (instance, geometry, primitive, t, barycentrics, normal, SBT offset) or the same miss, on a small top level whose
// triangles are flattened into one scene and on a top level of one instance of a larger, transformed bottom level.
#include <cmath>
#include <cstring>
#include <limits>

#include "accel/scenes.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel::test {
namespace {

// A handler that must never be called: packet-traceable rays meet no candidate that needs a shader.
struct NoCallbacks : HitHandler {
  AnyHitResult anyHit(const HitInfo&) override {
    ADD_FAILURE() << "any-hit called";
    return AnyHitResult::Accept;
  }
  void intersect(ProceduralCandidate&) override { ADD_FAILURE() << "intersect called"; }
};

// A deterministic stream of floats in [0, 1).
struct Lcg {
  uint32_t s;
  float next() {
    s = s * 1664525u + 1013904223u;
    return float(s >> 8) * (1.0f / 16777216.0f);
  }
};

// A bumpy grid of 2 x n x n triangles over [-2, 2]^2 (not flattened: more than a small bottom level's primitives).
Geometry terrain(uint32_t n) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x) {
      const float fx = -2 + 4.0f * float(x) / float(n), fy = -2 + 4.0f * float(y) / float(n);
      g.triangles.vertices.insert(g.triangles.vertices.end(), {fx, fy, 0.3f * std::sin(3 * fx) * std::cos(2 * fy)});
    }
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      g.triangles.indices.insert(g.triangles.indices.end(), {a, b, d, a, d, c});
    }
  return g;
}

// Packets of `rays` (random origins above the scene aimed down at it, some not allowed by Vulkan, some culled by
// their mask) under several lane masks, each lane against trace() of its ray alone.
void comparePackets(const Tlas& tlas, uint32_t seed) {
  Lcg r{seed};
  NoCallbacks none;
  int hits = 0, misses = 0;
  for (int packet = 0; packet < 64; ++packet) {
    Ray rays[kPacketRays];
    for (uint32_t i = 0; i < kPacketRays; ++i) {
      Ray& ray = rays[i];
      ray = rayFrom(-3 + 6 * r.next(), -3 + 6 * r.next(), 4 + r.next(), r.next() - 0.5f, r.next() - 0.5f, -1 - r.next(),
                    packet % 2 ? kRayOpaque : 0, 100.0f, 0.001f);
      const uint32_t odd = uint32_t(packet * kPacketRays + i) % 23;
      if (odd == 3) ray.direction[1] = std::numeric_limits<float>::quiet_NaN();  // not allowed: a miss
      if (odd == 5) ray.tMin = ray.tMax + 1;                                     // likewise
      if (odd == 7) ray.cullMask = 0x02;                                         // no instance has that bit
      if (odd == 11) ray.tMax = 4.0f;                                            // short of the scene
      ASSERT_TRUE(packetTraceable(tlas, ray)) << "packet " << packet << " ray " << i;
    }
    const uint32_t mask = packet % 3 == 0 ? 0xFFFFu : packet % 3 == 1 ? 0x5A5Au : 0x8001u;
    CommittedHit hits16[kPacketRays];
    const uint32_t found = tracePacket(tlas, rays, mask, hits16);
    EXPECT_EQ(found & ~mask, 0u);
    for (uint32_t i = 0; i < kPacketRays; ++i) {
      if (!((mask >> i) & 1)) continue;
      SCOPED_TRACE("packet " + std::to_string(packet) + " ray " + std::to_string(i));
      CommittedHit one;
      const bool hit = trace(tlas, rays[i], none, &one);
      ASSERT_EQ(((found >> i) & 1) != 0, hit);
      if (!hit) {
        ++misses;
        continue;
      }
      ++hits;
      const CommittedHit& p = hits16[i];
      EXPECT_EQ(p.t, one.t);
      EXPECT_EQ(p.instance, one.instance);
      EXPECT_EQ(p.geometry, one.geometry);
      EXPECT_EQ(p.primitive, one.primitive);
      EXPECT_EQ(p.hitKind, one.hitKind);
      EXPECT_EQ(p.sbtOffset, one.sbtOffset);
      EXPECT_EQ(p.triangle, one.triangle);
      EXPECT_EQ(p.u, one.u);
      EXPECT_EQ(p.v, one.v);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(p.ng[k], one.ng[k]);
    }
  }
  EXPECT_GT(hits, 100);  // both outcomes are exercised
  EXPECT_GT(misses, 50);
}

TEST(AccelPacket, FlattenedTopLevelCommitsWhatTraceCommits) {
  auto a = makeBlas({quads({0.5f, -0.5f}, kGeometryOpaque, 1.5f)});
  auto b = makeBlas({quad(0.0f, kGeometryOpaque, 1.0f), quad(-1.0f, kGeometryOpaque, 2.0f)});
  Instance i0 = translated(a, -1, 0, 0), i1 = translated(b, 1.2f, 0.5f, 0.25f), i2 = translated(a, 0.5f, -1.5f, -0.5f);
  i0.sbtOffset = 3;
  i1.customIndex = 9;
  i2.mask = 0x01;
  auto tlas = makeTlas({i0, i1, i2});
  ASSERT_TRUE(tlas->impl().flatScene) << "the small top level was not flattened";
  comparePackets(*tlas, 1);
}

TEST(AccelPacket, OneTransformedInstanceCommitsWhatTraceCommits) {
  auto blas = makeBlas({terrain(24)});
  Instance in = instanceOf(blas);
  // Rotated about z by 30 degrees, scaled by 1.25 and translated.
  const float c = 0.8660254f * 1.25f, s = 0.5f * 1.25f;
  const float m[3][4] = {{c, -s, 0, 0.25f}, {s, c, 0, -0.5f}, {0, 0, 1.25f, 0.125f}};
  std::memcpy(in.transform, m, sizeof m);
  in.sbtOffset = 2;
  in.mask = 0x01;
  auto tlas = makeTlas({in});
  ASSERT_FALSE(tlas->impl().flatScene);
  comparePackets(*tlas, 2);
}

// What needs a callback, or another shape of top level, is not traced as a packet (the caller traces it ray by ray).
TEST(AccelPacket, NotForRaysThatNeedCallbacksOrOtherTopLevels) {
  auto opaque = makeBlas({terrain(8)});
  auto noOpaque = makeBlas({quad(0, 0)});
  auto withBoxes = makeBlas({boxes({{0, 0, 0, 1, 1, 1}})});
  auto one = makeTlas({instanceOf(opaque)});
  const Ray down = rayFrom(0.1f, 0.2f, 5, 0, 0, -1);
  EXPECT_TRUE(packetTraceable(*one, down));
  for (uint32_t flags : {uint32_t(kRayCullBackFacingTriangles), uint32_t(kRayCullOpaque),
                         uint32_t(kRayTerminateOnFirstHit), uint32_t(kRayNoOpaque)})
    EXPECT_FALSE(packetTraceable(*one, rayFrom(0.1f, 0.2f, 5, 0, 0, -1, flags))) << std::hex << flags;
  auto nonOpaque = makeTlas({instanceOf(noOpaque)});
  EXPECT_FALSE(packetTraceable(*nonOpaque, down));                                         // the any-hit filter
  EXPECT_TRUE(packetTraceable(*nonOpaque, rayFrom(0.1f, 0.2f, 5, 0, 0, -1, kRayOpaque)));  // forced opaque
  EXPECT_FALSE(packetTraceable(*makeTlas({instanceOf(withBoxes)}), down));                 // boxes in reach
  EXPECT_FALSE(packetTraceable(*makeTlas({instanceOf(opaque), translated(opaque, 5, 0, 0)}), down));  // a hierarchy
}

}  // namespace
}  // namespace vkrt::accel::test
