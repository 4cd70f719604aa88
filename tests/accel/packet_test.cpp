// Packets (accel::tracePacket): up to 16 rays through one Embree packet query where each ray meets nothing that calls
// back (accel::packetTraceable). Away from ties, each lane must commit exactly what trace() commits for its ray alone:
// the same hit (instance, geometry, primitive, t, barycentrics, normal, SBT offset) or the same miss, on a small top
// level whose triangles are flattened into one scene and on a top level of one instance of a larger, transformed
// bottom level. Where a ray meets a shared edge or vertex, Embree's coherent traversal (a camera's packets) may keep
// the other triangle, or one whose t is a float or two away: hit or miss stays the same (watertight), t within
// four float epsilons of t (TiesAtSharedEdgesHitTheSameAtNearlyTheSameT).
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
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

// Packets of `rays` under several lane masks, each lane against trace() of its ray alone: scattered rays (random
// origins above the scene aimed down at it), or with `camera` a camera's (one origin per packet, the directions of a
// row of 16 pixels half a degree apart, as a ray generation batch traces them: Embree's coherent traversal); some
// not allowed by Vulkan, some culled by their mask.
void comparePackets(const Tlas& tlas, uint32_t seed, bool camera = false) {
  Lcg r{seed};
  NoCallbacks none;
  int hits = 0, misses = 0, coherent = 0;
  for (int packet = 0; packet < 64; ++packet) {
    Ray rays[kPacketRays];
    const float ox = -1 + 2 * r.next(), oy = -1 + 2 * r.next(), oz = 3 + r.next();
    const float ax = 0.6f * (r.next() - 0.5f), ay = 0.6f * (r.next() - 0.5f);
    for (uint32_t i = 0; i < kPacketRays; ++i) {
      Ray& ray = rays[i];
      if (camera) {
        ray = rayFrom(ox, oy, oz, ax + 0.008f * float(i), ay + 0.001f * float(i), -1.0f, packet % 2 ? kRayOpaque : 0,
                      100.0f, 0.001f);
      } else {
        ray = rayFrom(-3 + 6 * r.next(), -3 + 6 * r.next(), 4 + r.next(), r.next() - 0.5f, r.next() - 0.5f,
                      -1 - r.next(), packet % 2 ? kRayOpaque : 0, 100.0f, 0.001f);
      }
      const uint32_t odd = uint32_t(packet * kPacketRays + i) % 23;
      if (odd == 3) ray.direction[1] = std::numeric_limits<float>::quiet_NaN();  // not allowed: a miss
      if (odd == 5) ray.tMin = ray.tMax + 1;                                     // likewise
      if (odd == 7) ray.cullMask = 0x02;                                         // no instance has that bit
      if (odd == 11) ray.tMax = 4.0f;                                            // short of the scene
      ASSERT_TRUE(packetTraceable(tlas, ray)) << "packet " << packet << " ray " << i;
    }
    const uint32_t mask = packet % 3 == 0 ? 0xFFFFu : packet % 3 == 1 ? 0x5A5Au : 0x8001u;
    float dx[kPacketRays], dy[kPacketRays], dz[kPacketRays];
    int valid[kPacketRays];
    for (uint32_t i = 0; i < kPacketRays; ++i) {
      dx[i] = rays[i].direction[0], dy[i] = rays[i].direction[1], dz[i] = rays[i].direction[2];
      valid[i] = (mask >> i & 1) && !std::isnan(dy[i]) ? -1 : 0;
    }
    if (std::popcount(mask) >= 8) coherent += coherentDirections(dx, dy, dz, valid);
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
  EXPECT_GT(misses, camera ? 20 : 50);
  // The camera's packets go through the coherent traversal, the scattered ones (of 8 or 16 lanes) through the other.
  EXPECT_EQ(coherent, camera ? 43 : 0);
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
  comparePackets(*tlas, 3, true);
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
  comparePackets(*tlas, 4, true);
}

// Which packets are coherent: directions within about 8 degrees of the first valid lane's, whatever their lengths;
// invalid lanes do not count.
TEST(AccelPacket, CoherentDirectionsAreThoseWithinEightDegrees) {
  float dx[kPacketRays], dy[kPacketRays], dz[kPacketRays];
  int valid[kPacketRays];
  auto set = [&](float tanAngle) {  // lane i at angle atan(tanAngle * i / 15) from -z, about x, of length 1 + i
    for (uint32_t i = 0; i < kPacketRays; ++i) {
      const float len = 1.0f + float(i);
      dx[i] = 0, dy[i] = len * tanAngle * float(i) / 15.0f, dz[i] = -len;
      valid[i] = -1;
    }
  };
  set(std::tan(7.0f * 3.14159265f / 180.0f));
  EXPECT_TRUE(coherentDirections(dx, dy, dz, valid));
  set(std::tan(10.0f * 3.14159265f / 180.0f));
  EXPECT_FALSE(coherentDirections(dx, dy, dz, valid));
  valid[15] = valid[14] = valid[13] = 0;  // the widest lanes left out: the rest within 8 degrees
  EXPECT_TRUE(coherentDirections(dx, dy, dz, valid));
  set(0);
  dz[6] = 1;  // one lane the other way
  EXPECT_FALSE(coherentDirections(dx, dy, dz, valid));
  for (int& v : valid) v = 0;
  EXPECT_FALSE(coherentDirections(dx, dy, dz, valid));
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

// A camera's packets aimed exactly at the vertices of a flat grid (one instance) and at the middles of its edges
// (every ray on a shared edge or corner): the coherent traversal hits wherever trace() hits (no ray falls through a
// crack) at a t a float or two from trace()'s; which of the triangles at the point it keeps may differ (a tie; the
// specification leaves the choice to the implementation), and rays away from the grid miss both ways.
TEST(AccelPacket, TiesAtSharedEdgesHitTheSameAtNearlyTheSameT) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  constexpr uint32_t n = 32;
  for (uint32_t y = 0; y <= n; ++y)
    for (uint32_t x = 0; x <= n; ++x)
      g.triangles.vertices.insert(g.triangles.vertices.end(), {-2 + 4.0f * float(x) / n, -2 + 4.0f * float(y) / n, 0});
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      g.triangles.indices.insert(g.triangles.indices.end(), {a, b, d, a, d, c});
    }
  auto blas = makeBlas({g});
  NoCallbacks none;
  for (bool moved : {false, true}) {
    // The grid as it is, and moved by (0.5, 0.25, -1) (the rays aim at the moved points).
    const float tx = moved ? 0.5f : 0.0f, ty = moved ? 0.25f : 0.0f, tz = moved ? -1.0f : 0.0f;
    auto tlas = makeTlas({translated(blas, tx, ty, tz)});
    int hits = 0, misses = 0, coherent = 0;
    float maxApart = 0;  // in units of epsilon times t
    for (uint32_t row = 0; row <= n + 2; ++row)
      for (uint32_t x0 = 0; x0 + kPacketRays <= n + 1; x0 += 8)
        for (int middle = 0; middle < 2; ++middle) {
          Ray rays[kPacketRays];
          float dx[kPacketRays], dy[kPacketRays], dz[kPacketRays];
          int valid[kPacketRays];
          for (uint32_t i = 0; i < kPacketRays; ++i) {
            // Rows past the grid's last aim beside it (misses); `middle`: the middle of the horizontal edge.
            const float vx = -2 + 4.0f * float(x0 + i) / n + (middle ? 2.0f / n : 0.0f);
            const float vy = -2 + 4.0f * float(row) / n;
            rays[i] = rayFrom(0.1f, 0.05f, 30.0f, vx + tx - 0.1f, vy + ty - 0.05f, tz - 30.0f, 0, 100.0f, 0.0f);
            dx[i] = rays[i].direction[0], dy[i] = rays[i].direction[1], dz[i] = rays[i].direction[2];
            valid[i] = -1;
          }
          coherent += coherentDirections(dx, dy, dz, valid);
          CommittedHit packet[kPacketRays];
          const uint32_t found = tracePacket(*tlas, rays, 0xFFFFu, packet);
          for (uint32_t i = 0; i < kPacketRays; ++i) {
            SCOPED_TRACE("row " + std::to_string(row) + " x " + std::to_string(x0 + i) + " middle " +
                         std::to_string(middle) + (moved ? " moved" : ""));
            CommittedHit one;
            const bool hit = trace(*tlas, rays[i], none, &one);
            ASSERT_EQ(((found >> i) & 1) != 0, hit);
            if (!hit) {
              ++misses;
              continue;
            }
            ++hits;
            // A few floats apart at most: the kernels' rounding of t at the shared point differs by triangle (two
            // floats, one each side of 1, with Embree's AVX2 kernels).
            EXPECT_LE(std::fabs(packet[i].t - one.t), 4 * std::numeric_limits<float>::epsilon() * one.t);
            maxApart =
                std::max(maxApart, std::fabs(packet[i].t - one.t) / (std::numeric_limits<float>::epsilon() * one.t));
            EXPECT_EQ(packet[i].instance, one.instance);
            EXPECT_EQ(packet[i].geometry, one.geometry);
          }
        }
    std::printf("moved %d: the farthest t %.2f epsilon apart\n", int(moved), maxApart);
    EXPECT_GT(coherent, 100);
    EXPECT_GT(hits, 2000);
    EXPECT_GT(misses, 50);
  }
}

}  // namespace
}  // namespace vkrt::accel::test
