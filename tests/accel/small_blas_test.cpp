// Small bottom levels (16 primitives or fewer) have no Embree scene of their own: a top level holds their
// triangles in world space ("flattened", src/accel/tlas.cpp). Checked against the instanced path, which the same
// triangles take in a bottom level padded past the bound (with triangles no ray reaches): random triangles under
// random transforms (mirroring ones included), masks and ray flags, traced and queried, give the same hits. Small
// structures of boxes only are traversed without a scene (direct): checked the same way.
#include <algorithm>
#include <array>
#include <limits>
#include <random>
#include <set>
#include <utility>

#include "accel/scenes.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel::test {
namespace {

// Two triangles sharing an edge, at random, and the same followed by 20 far-away triangles (so past the bound).
struct Pair {
  std::shared_ptr<Blas> small, padded;
};
Pair randomPair(std::mt19937& rng, uint32_t flags) {
  std::uniform_real_distribution<float> u(-1, 1);
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = flags;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) g.triangles.vertices.push_back(2 * u(rng));
  g.triangles.indices = {0, 1, 2, 2, 1, 3};
  Geometry padded = g;
  for (uint32_t k = 0; k < 20; ++k) {
    const uint32_t base = uint32_t(padded.triangles.vertices.size() / 3);
    const float x = 1000.0f + 3.0f * float(k);
    padded.triangles.vertices.insert(padded.triangles.vertices.end(),
                                     {x, 1000, 1000, x + 1, 1000, 1000, x, 1001, 1000});
    padded.triangles.indices.insert(padded.triangles.indices.end(), {base, base + 1, base + 2});
  }
  return {makeBlas({g}), makeBlas({padded})};
}

struct Outcome {
  bool hit = false;
  float t = 0, u = 0, v = 0;
  uint32_t instance = 0, primitive = 0, hitKind = 0;
  // The any-hit candidates (instance, primitive) at or before the committed hit: those are offered whatever order
  // the traversal meets candidates in (later ones may be culled by a closer commit, depending on that order).
  std::set<std::pair<uint32_t, uint32_t>> anyHitsBefore;
};

Outcome traced(const Tlas& tlas, const Ray& ray) {
  Recorder rec;
  const Traced t = traceOnce(tlas, ray, rec);
  Outcome o;
  o.hit = t.hit;
  for (const HitInfo& h : rec.anyHits)
    if (t.hit && h.t <= t.info.t * (1 + 1e-5f)) o.anyHitsBefore.insert({h.instanceIndex, h.primitiveIndex});
  if (t.hit) {
    o.t = t.info.t;
    o.u = t.info.barycentrics[0];
    o.v = t.info.barycentrics[1];
    o.instance = t.info.instanceIndex;
    o.primitive = t.info.primitiveIndex;
    o.hitKind = t.info.hitKind;
  }
  return o;
}

// Instance `i` of a random scene: a random transform near a scaling by 1.2 (every third mirroring) and mask 0x0F
// (every fourth) or 0xF0.
Instance randomlyPlaced(std::mt19937& rng, uint32_t i) {
  std::uniform_real_distribution<float> u(-1, 1);
  Instance in;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) in.transform[r][c] = (r == c ? 1.2f : 0.0f) + 0.4f * u(rng);
    in.transform[r][3] = 1.5f * u(rng);
  }
  if (i % 3 == 0)
    for (int c = 0; c < 4; ++c) in.transform[2][c] = -in.transform[2][c];
  in.mask = i % 4 == 3 ? 0x0F : 0xF0;
  return in;
}

TEST(AccelSmallBlas, FlattenedTrianglesTraceAsInstancedOnes) {
  std::mt19937 rng(77);
  std::uniform_real_distribution<float> u(-1, 1);
  const uint32_t rayFlags[] = {0,
                               kRayCullBackFacingTriangles,
                               kRayCullFrontFacingTriangles,
                               kRayNoOpaque,
                               kRayTerminateOnFirstHit | kRayOpaque,
                               kRaySkipTriangles,
                               kRayCullOpaque};
  int hits = 0, compared = 0;
  for (int scene = 0; scene < 12; ++scene) {
    // Eight instances of random pairs (half non-opaque), random transforms (every third mirroring), masks and flags.
    std::vector<Instance> smallInstances, paddedInstances;
    std::vector<Pair> pairs;  // (instances do not own their Blases)
    for (uint32_t i = 0; i < 8; ++i) {
      const Pair& p = pairs.emplace_back(randomPair(rng, i % 2 ? kGeometryOpaque : 0u));
      Instance in = randomlyPlaced(rng, i);
      in.customIndex = i;
      in.flags = i == 5 ? uint32_t(kInstanceTriangleFlipFacing) : i == 6 ? uint32_t(kInstanceForceOpaque) : 0u;
      in.blas = p.small.get();
      smallInstances.push_back(in);
      in.blas = p.padded.get();
      paddedInstances.push_back(in);
    }
    auto flat = makeTlas(smallInstances), instanced = makeTlas(paddedInstances);
    for (int r = 0; r < 200; ++r) {
      Ray ray = rayFrom(3 * u(rng), 3 * u(rng), -6, 0.3f * u(rng), 0.3f * u(rng), 1, rayFlags[r % 7], 20.0f);
      ray.cullMask = r % 5 == 0 ? 0x0F : 0xFF;
      const Outcome a = traced(*flat, ray), b = traced(*instanced, ray);
      SCOPED_TRACE("scene " + std::to_string(scene) + ", ray " + std::to_string(r));
      ++compared;
      ASSERT_EQ(a.hit, b.hit);
      // Which hit TerminateOnFirstHit commits is the traversal's first: any of them.
      if (!a.hit || (ray.flags & kRayTerminateOnFirstHit)) continue;
      EXPECT_EQ(a.anyHitsBefore, b.anyHitsBefore);
      ++hits;
      EXPECT_TRUE(nearHit(a.t, b.t, 20)) << a.t << " vs " << b.t;
      EXPECT_EQ(a.instance, b.instance);
      EXPECT_EQ(a.primitive, b.primitive);
      EXPECT_EQ(a.hitKind, b.hitKind);
      EXPECT_NEAR(a.u, b.u, 1e-3f);
      EXPECT_NEAR(a.v, b.v, 1e-3f);
    }
    // Ray queries that confirm every candidate: the same committed hit.
    for (int r = 0; r < 50; ++r) {
      Ray ray = rayFrom(3 * u(rng), 3 * u(rng), -6, 0.3f * u(rng), 0.3f * u(rng), 1, rayFlags[r % 4], 20.0f);
      RayQuery qa, qb;
      queryInitialize(qa, flat.get(), ray);
      queryInitialize(qb, instanced.get(), ray);
      int ca = 0, cb = 0;
      while (queryProceed(qa)) ++ca, queryConfirm(qa);
      while (queryProceed(qb)) ++cb, queryConfirm(qb);
      EXPECT_EQ(ca, cb) << "candidates, ray " << r;
      EXPECT_EQ(qa.committed.type, qb.committed.type);
      EXPECT_EQ(qa.committed.instance, qb.committed.instance);
      EXPECT_EQ(qa.committed.primitive, qb.committed.primitive);
    }
  }
  EXPECT_GT(hits, compared / 10);
}

// Thousands of one-triangle structures under one top level (as the CTS's build.*.level_instances.* cases make):
// each ray hits the one triangle in its cell, with the instance, custom index, primitive and distance it must.
TEST(AccelSmallBlas, ThousandsOfOneTriangleStructuresHitExactly) {
  constexpr uint32_t kSide = 64;
  std::vector<Instance> instances;
  std::vector<std::shared_ptr<Blas>> blases;  // (instances do not own them)
  for (uint32_t k = 0; k < kSide * kSide; ++k) {
    Geometry g;
    g.kind = Geometry::Triangles;
    g.triangles.flags = kGeometryOpaque;
    const float x = float(k % kSide), y = float(k / kSide);
    g.triangles.vertices = {x, y, 1, x + 1, y + 0.5f, 1, x + 0.5f, y + 1, 1};
    g.triangles.indices = {0, 1, 2};
    blases.push_back(makeBlas({g}));
    Instance in = instanceOf(blases.back());
    in.customIndex = k;
    instances.push_back(in);
  }
  auto tlas = makeTlas(instances);
  for (uint32_t k = 0; k < kSide * kSide; ++k) {
    const float x = float(k % kSide) + 0.5f, y = float(k / kSide) + 0.5f;
    const Traced t = traceOnce(*tlas, rayFrom(x, y, 0, 0, 0, 1));
    ASSERT_TRUE(t.hit) << k;
    EXPECT_EQ(t.info.instanceIndex, k);
    EXPECT_EQ(t.info.customIndex, k);
    EXPECT_EQ(t.info.primitiveIndex, 0u);
    EXPECT_TRUE(nearHit(t.info.t, 1.0f)) << t.info.t;  // (the kernels' reciprocal estimates: hit_distance.hpp)
  }
}

// Past the bound of flattened triangles a top level holds (2^20), the remaining instances of small structures are
// instanced, their structure's scene made then: 65,537 instances of a 16-triangle structure (the last one past the
// bound) are all hit where they must be, flattened or not.
TEST(AccelSmallBlas, InstancesPastTheFlattenedBoundAreInstanced) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  for (uint32_t q = 0; q < 8; ++q)  // 8 quads = 16 triangles side by side over [0, 8] x [0, 1] at z = 1
    addQuad(g.triangles, float(q), 0, float(q + 1), 1, 1);
  auto blas = makeBlas({g});
  constexpr uint32_t kInstances = 65537, kRow = 256;
  std::vector<Instance> instances(kInstances, instanceOf(blas));
  for (uint32_t k = 0; k < kInstances; ++k) {
    instances[k].transform[0][3] = 10.0f * float(k % kRow);
    instances[k].transform[1][3] = 2.0f * float(k / kRow);
    instances[k].customIndex = k;
  }
  auto tlas = makeTlas(instances);
  for (uint32_t k : {0u, 1u, 65535u, 65536u}) {
    for (uint32_t q : {0u, 7u}) {
      const float x = 10.0f * float(k % kRow) + float(q) + 0.2f, y = 2.0f * float(k / kRow) + 0.7f;
      const Traced t = traceOnce(*tlas, rayFrom(x, y, 0, 0, 0, 1));
      ASSERT_TRUE(t.hit) << "instance " << k << ", quad " << q;
      EXPECT_EQ(t.info.instanceIndex, k);
      EXPECT_EQ(t.info.customIndex, k);
      EXPECT_EQ(t.info.primitiveIndex, 2 * q + 1) << "the quad's second triangle (x0 y0, x1 y1, x0 y1)";
      EXPECT_TRUE(nearHit(t.info.t, 1.0f)) << t.info.t;
    }
  }
}

// Small structures of boxes only are direct: no Embree scene at all, traversal offers their boxes one by one. Every
// box is found by the ray through its cell, through either of its two instances, with the instance and primitive it
// must report, and no structure has a scene.
TEST(AccelSmallBlas, ThousandsOfOneBoxStructuresAreDirectAndHit) {
  constexpr uint32_t kCount = 4096, kRow = 64;
  std::vector<std::shared_ptr<Blas>> blases;
  for (uint32_t k = 0; k < kCount; ++k) {
    const float x = float(k % kRow), y = float(k / kRow);
    blases.push_back(makeBlas({boxes({{x + 0.25f, y + 0.25f, 1, x + 0.75f, y + 0.75f, 2}})}));
  }
  std::vector<Instance> instances;
  for (int copy = 0; copy < 2; ++copy)
    for (uint32_t k = 0; k < kCount; ++k) {
      instances.push_back(translated(blases[k], 0, 0, copy ? 10.0f : 0.0f));
      instances.back().customIndex = k;
    }
  auto tlas = makeTlas(instances);
  size_t notDirect = 0, withScene = 0;
  for (const auto& b : blases) notDirect += !b->impl->direct;
  for (size_t i = 0; i < instances.size(); ++i) withScene += tlas->impl().records[i].scene != nullptr;
  EXPECT_EQ(notDirect, 0u);
  EXPECT_EQ(withScene, 0u);
  EXPECT_EQ(tlas->impl().leafItems.size(), instances.size()) << "every instance is in the hierarchy";
  for (uint32_t k = 0; k < kCount; k += 37) {
    for (int copy = 0; copy < 2; ++copy) {
      const float x = float(k % kRow) + 0.5f, y = float(k / kRow) + 0.5f;
      Recorder rec;
      rec.onIntersect = [](ProceduralCandidate& c) { c.commit(c.tMin(), 0, false); };
      // Rays from below meet the lower copy first; rays from above z = 20 going down meet the upper one first.
      const Traced t = traceOnce(*tlas, copy ? rayFrom(x, y, 20, 0, 0, -1) : rayFrom(x, y, 0, 0, 0, 1), rec);
      ASSERT_TRUE(t.hit) << "structure " << k << ", copy " << copy;
      EXPECT_FALSE(t.info.triangle);
      EXPECT_EQ(t.info.instanceIndex, k + uint32_t(copy) * kCount);
      EXPECT_EQ(t.info.customIndex, k);
      EXPECT_EQ(t.info.primitiveIndex, 0u);
    }
  }
}

// Random small structures of boxes (direct), against the same boxes in structures padded past the bound with boxes
// no ray reaches (an Embree scene each): points, flat boxes, inactive boxes and boxes beyond Embree's range
// included, in one or two geometries, opaque or not, under random transforms (mirroring ones included), masks and
// ray flags, traced (the intersection shader committing each box's entry distance) and queried (every candidate
// listed): the same boxes are offered and the same hit committed.
struct BoxPair {
  std::shared_ptr<Blas> direct, padded;
};
BoxPair randomBoxes(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-2, 2);
  std::uniform_int_distribution<int> kind(0, 9), count(1, 6);
  std::vector<Geometry> geometries;
  const int geometryCount = kind(rng) < 3 ? 2 : 1;
  for (int g = 0; g < geometryCount; ++g) {
    std::vector<std::array<float, 6>> list;
    for (int b = count(rng) / geometryCount; b >= 0; --b) {
      std::array<float, 6> box;
      for (int k = 0; k < 3; ++k) {
        const float a = u(rng), c = u(rng);
        box[k] = std::min(a, c), box[k + 3] = std::max(a, c);
      }
      switch (kind(rng)) {
        case 0: box[2] = box[5]; break;                                    // flat in z
        case 1: box[3] = box[0], box[4] = box[1], box[5] = box[2]; break;  // a point
        case 2: box[0] = std::numeric_limits<float>::quiet_NaN(); break;   // inactive
        case 3: box[3] = 4e18f; break;                                     // beyond Embree's range
        default: break;
      }
      list.push_back(box);
    }
    geometries.push_back(boxes(list, g == 1 || kind(rng) < 5 ? kGeometryOpaque : 0u));
  }
  std::vector<Geometry> padded = geometries;
  for (uint32_t k = 0; k < 20; ++k) {
    const float x = 1000.0f + 3.0f * float(k);
    padded.back().aabbs.boxes.insert(padded.back().aabbs.boxes.end(), {x, 1000, 1000, x + 1, 1001, 1001});
  }
  return {makeBlas(geometries), makeBlas(padded)};
}

// The distance at which the object-space ray of `c` enters its box (clamped into the candidate's interval).
float entryOf(const ProceduralCandidate& c, const Blas& blas) {
  const HitInfo& h = c.info();
  const float* b = blas.geometries()[h.geometryIndex].aabbs.boxes.data() + 6 * size_t(h.primitiveIndex);
  double lo = c.tMin();
  for (int a = 0; a < 3; ++a) {
    if (h.objectRayDirection[a] == 0) continue;
    const double t0 = (double(b[a]) - h.objectRayOrigin[a]) / h.objectRayDirection[a];
    const double t1 = (double(b[a + 3]) - h.objectRayOrigin[a]) / h.objectRayDirection[a];
    lo = std::max(lo, std::min(t0, t1));
  }
  return std::min(float(lo), c.tMax());
}

struct BoxOutcome {
  bool hit = false;
  float t = 0;
  uint32_t instance = 0, geometry = 0, primitive = 0;
  std::set<std::array<uint32_t, 3>> offeredBefore;  // boxes offered entering before the committed hit
};

BoxOutcome tracedBoxes(const Tlas& tlas, const std::vector<const Blas*>& blasOf, const Ray& ray) {
  Recorder rec;
  std::vector<std::pair<std::array<uint32_t, 3>, float>> offered;
  rec.onIntersect = [&](ProceduralCandidate& c) {
    const HitInfo& h = c.info();
    const float t = entryOf(c, *blasOf[h.instanceIndex]);
    offered.push_back({{h.instanceIndex, h.geometryIndex, h.primitiveIndex}, t});
    c.commit(t, 1, false);
  };
  const Traced r = traceOnce(tlas, ray, rec);
  BoxOutcome o;
  o.hit = r.hit;
  if (!r.hit) return o;
  o.t = r.info.t;
  o.instance = r.info.instanceIndex;
  o.geometry = r.info.geometryIndex;
  o.primitive = r.info.primitiveIndex;
  for (const auto& [ids, t] : offered)
    if (t < r.info.t * (1 - 1e-4f)) o.offeredBefore.insert(ids);
  return o;
}

TEST(AccelSmallBlas, DirectBoxesTraceAsInstancedOnes) {
  std::mt19937 rng(91);
  std::uniform_real_distribution<float> u(-1, 1);
  const uint32_t rayFlags[] = {
      0, kRayOpaque, kRayNoOpaque, kRayCullOpaque, kRayCullNoOpaque, kRaySkipAabbs, kRayTerminateOnFirstHit};
  int hits = 0, compared = 0, candidates = 0;
  for (int scene = 0; scene < 12; ++scene) {
    std::vector<Instance> directInstances, paddedInstances;
    std::vector<BoxPair> pairs;
    std::vector<const Blas*> blasOf;
    for (uint32_t i = 0; i < 8; ++i) {
      const BoxPair& p = pairs.emplace_back(randomBoxes(rng));
      ASSERT_TRUE(p.direct->impl->direct);
      ASSERT_FALSE(p.padded->impl->direct);
      Instance in = randomlyPlaced(rng, i);
      in.flags = i == 5 ? uint32_t(kInstanceForceOpaque) : i == 6 ? uint32_t(kInstanceForceNoOpaque) : 0u;
      in.blas = p.direct.get();
      directInstances.push_back(in);
      in.blas = p.padded.get();
      paddedInstances.push_back(in);
      blasOf.push_back(p.direct.get());
    }
    auto direct = makeTlas(directInstances), padded = makeTlas(paddedInstances);
    for (int r = 0; r < 300; ++r) {
      Ray ray = rayFrom(3 * u(rng), 3 * u(rng), -6, 0.3f * u(rng), 0.3f * u(rng), 1, rayFlags[r % 7], 20.0f);
      if (r % 11 == 0) ray.direction[0] = ray.direction[1] = 0;  // zero components: the slab test's other branch
      ray.cullMask = r % 5 == 0 ? 0x0F : 0xFF;
      const BoxOutcome a = tracedBoxes(*direct, blasOf, ray), b = tracedBoxes(*padded, blasOf, ray);
      SCOPED_TRACE("scene " + std::to_string(scene) + ", ray " + std::to_string(r));
      ++compared;
      ASSERT_EQ(a.hit, b.hit);
      if (!a.hit || (ray.flags & kRayTerminateOnFirstHit)) continue;  // (the first hit met: any of them)
      ++hits;
      EXPECT_EQ(a.t, b.t);
      EXPECT_EQ(a.instance, b.instance);
      EXPECT_EQ(a.geometry, b.geometry);
      EXPECT_EQ(a.primitive, b.primitive);
      EXPECT_EQ(a.offeredBefore, b.offeredBefore);
    }
    for (int r = 0; r < 100; ++r) {
      const Ray ray = rayFrom(3 * u(rng), 3 * u(rng), -6, 0.3f * u(rng), 0.3f * u(rng), 1, rayFlags[r % 6], 20.0f);
      std::set<std::array<uint32_t, 3>> seen[2];
      for (int k = 0; k < 2; ++k) {
        RayQuery q;
        queryInitialize(q, (k ? padded : direct).get(), ray);
        while (queryProceed(q)) {
          EXPECT_EQ(q.candidate.type, 2);
          seen[k].insert({q.candidate.instance, q.candidate.geometry, q.candidate.primitive});
        }
      }
      EXPECT_EQ(seen[0], seen[1]) << "query candidates, ray " << r;
      candidates += int(seen[0].size());
    }
  }
  EXPECT_GT(hits, compared / 10);
  EXPECT_GT(candidates, 100);
}

}  // namespace
}  // namespace vkrt::accel::test
