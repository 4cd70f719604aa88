// vkrt's own instance level (tlas.cpp: a hierarchy over the instance records, built by rtcBuildBVH, refit by an
// update; traverse.cpp enters each instance's Blas scene): thousands of overlapping instances, rotated and scaled,
// with masks, inactive ones and flattened small bottom levels among them, against the closest hit computed here in
// double from the instances' placements alone. Traced rays, occlusion rays and ray queries must all agree with it.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <tuple>

#include "accel/scenes.hpp"
#include "accel/structures.hpp"

namespace vkrt::accel::test {
namespace {

// A tile: a grid of w x h unit quads at z = 0 covering [0, w] x [0, h]; quad q = cy * w + cx holds triangles 2q
// (below the diagonal: x - cx > y - cy) and 2q + 1. 5 x 4 (40 triangles) gets an Embree scene; 2 x 2 (8) is small
// and flattened into the top level.
Geometry tile(int w, int h) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) addQuad(g.triangles, float(x), float(y), float(x + 1), float(y + 1), 0);
  return g;
}

struct Placement {
  int tile = 0;          // 0: the 5 x 4 tile, 1: the 2 x 2 one
  int quarterTurns = 0;  // about z
  float scale = 1, x = 0, y = 0, z = 0;
  uint32_t mask = 0xFF;
  bool active = true;
};

constexpr int kTileW[2] = {5, 2}, kTileH[2] = {4, 2};

Instance placed(const Placement& p, const std::shared_ptr<const Blas> blases[2]) {
  Instance in;
  in.blas = p.active ? blases[p.tile].get() : nullptr;
  const float c[4] = {1, 0, -1, 0}, s[4] = {0, 1, 0, -1};
  const float cs = c[p.quarterTurns] * p.scale, sn = s[p.quarterTurns] * p.scale;
  const float m[3][4] = {{cs, -sn, 0, p.x}, {sn, cs, 0, p.y}, {0, 0, 1, p.z}};
  std::memcpy(in.transform, m, sizeof m);
  in.mask = p.mask;
  in.customIndex = 0;
  return in;
}

struct Expected {
  bool sure = true;  // false: the ray passes near an edge of a candidate instance (not checked)
  bool hit = false;
  uint32_t instance = 0, primitive = 0;
  float t = 0;
};

// The closest instance a ray along +z from (px, py, -1) with `cull` meets, from the placements (double).
Expected expect(const std::vector<Placement>& placements, double px, double py, uint32_t cull) {
  Expected e;
  double bestZ = HUGE_VAL;
  std::optional<double> unsureZ;
  constexpr double kMargin = 1e-3;
  for (uint32_t i = 0; i < placements.size(); ++i) {
    const Placement& p = placements[i];
    if (!p.active || !(p.mask & cull)) continue;
    const double c[4] = {1, 0, -1, 0}, s[4] = {0, 1, 0, -1};
    const double dx = px - p.x, dy = py - p.y;
    // The inverse rotation (a transpose), then the inverse scale.
    const double ox = (c[p.quarterTurns] * dx + s[p.quarterTurns] * dy) / p.scale;
    const double oy = (-s[p.quarterTurns] * dx + c[p.quarterTurns] * dy) / p.scale;
    const double w = kTileW[p.tile], h = kTileH[p.tile];
    if (ox < -kMargin || oy < -kMargin || ox > w + kMargin || oy > h + kMargin) continue;
    const double fx = ox - std::floor(ox), fy = oy - std::floor(oy);
    const bool nearEdge = ox < kMargin || oy < kMargin || ox > w - kMargin || oy > h - kMargin || fx < kMargin ||
                          fy < kMargin || fx > 1 - kMargin || fy > 1 - kMargin || std::fabs(fx - fy) < kMargin;
    if (nearEdge) {
      unsureZ = std::min(unsureZ.value_or(HUGE_VAL), double(p.z));
      continue;
    }
    if (p.z < bestZ) {
      bestZ = p.z;
      e.hit = true;
      e.instance = i;
      const uint32_t q = uint32_t(std::floor(oy)) * uint32_t(w) + uint32_t(std::floor(ox));
      e.primitive = 2 * q + (fx > fy ? 0 : 1);
      e.t = float(p.z + 1.0);
    }
  }
  if (unsureZ && *unsureZ <= bestZ + 1e-3) e.sure = false;
  return e;
}

// A deterministic generator (no dependence on the standard library's distributions).
struct Lcg {
  uint64_t s;
  uint32_t next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return uint32_t(s >> 33);
  }
  double unit() { return next() / double(1u << 31); }
};

std::vector<Placement> randomPlacements(uint32_t count, uint64_t seed) {
  Lcg r{seed};
  const uint32_t masks[6] = {0x01, 0x02, 0x04, 0x0F, 0xF0, 0xFF};
  std::vector<Placement> out(count);
  for (uint32_t i = 0; i < count; ++i) {
    Placement& p = out[i];
    p.tile = r.next() % 4 == 0 ? 1 : 0;
    p.quarterTurns = int(r.next() % 4);
    p.scale = r.next() % 3 == 0 ? 2.0f : 1.0f;
    p.x = float(r.unit() * 60);
    p.y = float(r.unit() * 60);
    p.z = 1.0f + 0.0137f * float((i * 7919u) % count);  // distinct depths
    p.mask = r.next() % 17 == 0 ? 0 : masks[r.next() % 6];
    p.active = r.next() % 23 != 0;
  }
  return out;
}

std::shared_ptr<Tlas> buildPlaced(const std::vector<Placement>& placements, const std::shared_ptr<const Blas> blases[2],
                                  const BuildOptions& options = {}) {
  std::vector<Instance> instances;
  for (const Placement& p : placements) instances.push_back(placed(p, blases));
  return makeTlas(std::move(instances), options);
}

// Traces `rays` random rays through `tlas` three ways and counts the disagreements with expect().
size_t countWrong(const Tlas& tlas, const std::vector<Placement>& placements, uint64_t seed, int rays,
                  int* checked = nullptr) {
  Lcg r{seed};
  const uint32_t culls[4] = {0xFF, 0x01, 0x06, 0xF0};
  size_t wrong = 0;
  int sure = 0;
  for (int k = 0; k < rays; ++k) {
    const float px = float(-5 + r.unit() * 75), py = float(-5 + r.unit() * 75);
    const uint32_t cull = culls[r.next() % 4];
    const Expected e = expect(placements, px, py, cull);
    if (!e.sure) continue;
    ++sure;
    Ray ray = rayFrom(px, py, -1, 0, 0, 1);
    ray.cullMask = cull;
    const Traced t = traceOnce(tlas, ray);
    bool ok = t.hit == e.hit && (!e.hit || (t.info.instanceIndex == e.instance &&
                                            t.info.primitiveIndex == e.primitive && nearHit(t.info.t, e.t, 60)));
    // TerminateOnFirstHit: an occlusion query; any hit will do.
    Ray shadow = ray;
    shadow.flags = kRayTerminateOnFirstHit;
    ok &= traceOnce(tlas, shadow).hit == e.hit;
    // ... and where nobody reads which hit ended it (a shadow ray without a closest-hit shader): Embree's occlusion
    // query alone, no filter.
    Recorder unread;
    ok &= trace(tlas, shadow, unread, static_cast<CommittedHit*>(nullptr)) == e.hit && unread.anyHits.empty();
    // A ray query over opaque triangles: no candidate for the shader, the closest committed.
    RayQuery q;
    queryInitialize(q, &tlas, ray);
    ok &= !queryProceed(q);
    ok &= (q.committed.type == 1) == e.hit &&
          (!e.hit || (q.committed.instance == e.instance && q.committed.primitive == e.primitive));
    if (!ok && ++wrong <= 5)
      ADD_FAILURE() << "ray at (" << px << ", " << py << ") cull " << cull << ": expected " << e.hit << " instance "
                    << e.instance << " primitive " << e.primitive << " t " << e.t << "; traced " << t.hit
                    << " instance " << t.info.instanceIndex << " primitive " << t.info.primitiveIndex << " t "
                    << t.info.t << "; query " << int(q.committed.type) << " instance " << q.committed.instance;
  }
  if (checked) *checked = sure;
  return wrong;
}

TEST(AccelInstanceHierarchy, ThousandsOfOverlappingInstancesGiveTheClosestHit) {
  const std::shared_ptr<const Blas> blases[2] = {makeBlas({tile(5, 4)}), makeBlas({tile(2, 2)})};
  const auto placements = randomPlacements(3000, 1);
  for (const BuildOptions& options :
       {BuildOptions{}, BuildOptions{.preferFastTrace = true}, BuildOptions{.preferFastBuild = true}}) {
    auto tlas = buildPlaced(placements, blases, options);
    ASSERT_TRUE(tlas);
    // Both levels are there: a hierarchy over the big tiles, the small ones flattened.
    EXPECT_GT(tlas->impl().nodes.size(), 100u);
    EXPECT_TRUE(tlas->impl().flatScene);
    int checked = 0;
    EXPECT_EQ(countWrong(*tlas, placements, 2, 3000, &checked), 0u);
    EXPECT_GT(checked, 2500);
  }
}

// Enough instances for the parallel parts of the build (records made in chunks, the builder's tree copied as 256
// subtrees placed from their counts): the arrays are laid out as one depth-first copy lays them (a node before its
// children, the first child's subtree before the second's, leaf items in the order their leaves are met), every
// instance of the hierarchy is in exactly one leaf, every box holds the boxes below it, and rays find the closest hit.
TEST(AccelInstanceHierarchy, TensOfThousandsOfInstancesAreLaidOutDepthFirst) {
  const std::shared_ptr<const Blas> blases[2] = {makeBlas({tile(5, 4)}), makeBlas({tile(2, 2)})};
  const auto placements = randomPlacements(40000, 11);
  auto tlas = buildPlaced(placements, blases);
  ASSERT_TRUE(tlas);
  const Tlas::Impl& impl = tlas->impl();
  ASSERT_GT(impl.nodes.size(), 4096u);  // deeper than the split into subtrees
  uint32_t nextNode = 0, nextItem = 0;
  std::vector<int> seen(placements.size(), 0);
  size_t misplaced = 0, unbounded = 0;
  auto inside = [](const float* lo, const float* hi, const float* outerLo, const float* outerHi) {
    for (int k = 0; k < 3; ++k)
      if (lo[k] < outerLo[k] || hi[k] > outerHi[k]) return false;
    return true;
  };
  std::function<void(uint32_t)> walk = [&](uint32_t ref) {
    if (ref & detail::kLeafRef) {
      uint32_t count, one;
      const uint32_t* items = detail::leafInstances(impl.leafItems, ref, &count, &one);
      if (count > 1 && one != nextItem) ++misplaced;
      for (uint32_t k = 0; k < count; ++k) {
        if (nextItem + k >= impl.leafItems.size() || impl.leafItems[nextItem + k] != items[k]) ++misplaced;
        if (items[k] < seen.size()) ++seen[items[k]];
      }
      nextItem += count;
      return;
    }
    if (ref != nextNode++ || ref >= impl.nodes.size()) {
      ++misplaced;
      return;
    }
    const detail::BvhNode& node = impl.nodes[ref];
    for (int k = 0; k < 2; ++k) {
      const uint32_t child = node.child[k];
      if (!(child & detail::kLeafRef) && child < impl.nodes.size())
        for (int c = 0; c < 2; ++c)
          if (!inside(impl.nodes[child].lower[c], impl.nodes[child].upper[c], node.lower[k], node.upper[k]))
            ++unbounded;
      walk(child);
    }
  };
  walk(impl.root);
  EXPECT_EQ(misplaced, 0u);
  EXPECT_EQ(unbounded, 0u);
  EXPECT_EQ(nextNode, impl.nodes.size());
  EXPECT_EQ(nextItem, impl.leafItems.size());
  size_t inHierarchy = 0, wrongCount = 0;  // instances in no leaf or in several, or in one and not in the hierarchy
  for (size_t i = 0; i < placements.size(); ++i) {
    inHierarchy += impl.records[i].scene != nullptr;
    wrongCount += seen[i] != (impl.records[i].scene != nullptr ? 1 : 0);
  }
  EXPECT_GT(inHierarchy, 20000u);
  EXPECT_EQ(wrongCount, 0u);
  int checked = 0;
  EXPECT_EQ(countWrong(*tlas, placements, 12, 600, &checked), 0u);
  EXPECT_GT(checked, 200);
}

TEST(AccelInstanceHierarchy, UpdateRefitsTheHierarchyToNewTransforms) {
  const std::shared_ptr<const Blas> blases[2] = {makeBlas({tile(5, 4)}), makeBlas({tile(2, 2)})};
  const auto before = randomPlacements(2000, 3);
  auto after = randomPlacements(2000, 4);
  for (size_t i = 0; i < after.size(); ++i) {  // the same instances, active and visible, elsewhere
    after[i].tile = before[i].tile;
    after[i].active = before[i].active;
    after[i].mask = before[i].mask;
  }
  auto tlas = buildPlaced(before, blases, BuildOptions{.allowUpdate = true});
  ASSERT_TRUE(tlas);
  std::vector<Instance> instances;
  for (const Placement& p : after) instances.push_back(placed(p, blases));
  std::string error;
  auto moved = tlas->update(instances, &error);
  ASSERT_TRUE(moved) << error;
  // A refit: the same tree, new bounds.
  ASSERT_EQ(moved->impl().nodes.size(), tlas->impl().nodes.size());
  EXPECT_EQ(moved->impl().leafItems, tlas->impl().leafItems);
  EXPECT_EQ(moved->impl().root, tlas->impl().root);
  bool sameChildren = true, boundsMoved = false;
  for (size_t n = 0; n < tlas->impl().nodes.size(); ++n) {
    const auto &a = tlas->impl().nodes[n], &b = moved->impl().nodes[n];
    sameChildren &= a.child[0] == b.child[0] && a.child[1] == b.child[1];
    boundsMoved |= std::memcmp(a.lower, b.lower, sizeof a.lower) != 0;
  }
  EXPECT_TRUE(sameChildren);
  EXPECT_TRUE(boundsMoved);
  EXPECT_EQ(countWrong(*moved, after, 5, 2000), 0u);
  EXPECT_EQ(countWrong(*tlas, before, 6, 1000), 0u);  // the source is unchanged

  // Another set of instances in the hierarchy (one made inactive): built anew, still right.
  auto fewer = after;
  for (size_t i = 0; i < fewer.size(); ++i)
    if (fewer[i].active && fewer[i].mask && fewer[i].tile == 0) {
      fewer[i].active = false;
      break;
    }
  instances.clear();
  for (const Placement& p : fewer) instances.push_back(placed(p, blases));
  auto rebuilt = moved->update(instances, &error);
  ASSERT_TRUE(rebuilt) << error;
  EXPECT_EQ(rebuilt->impl().leafItems.size() + 1, moved->impl().leafItems.size());
  EXPECT_EQ(countWrong(*rebuilt, fewer, 7, 2000), 0u);
}

// Shaders across instances of the hierarchy (bottom levels too big to be flattened): ten stacked instances of a
// non-opaque tile and of 20 boxes, entered in the hierarchy's order, whatever their index order.
TEST(AccelInstanceHierarchy, AnyHitAndIntersectionShadersAcrossInstances) {
  const std::shared_ptr<const Blas> tiles = makeBlas({[] {
    Geometry g = tile(5, 4);
    g.triangles.flags = 0;  // non-opaque: the any-hit shader decides
    return g;
  }()});
  std::vector<std::array<float, 6>> list;
  for (int k = 0; k < 20; ++k)
    list.push_back({float(k % 5), float(k / 5), -0.25f, float(k % 5 + 1), float(k / 5 + 1), 0.25f});
  const std::shared_ptr<const Blas> cubes = makeBlas({boxes(list, 0)});
  const uint32_t order[10] = {7, 2, 9, 0, 5, 3, 8, 1, 6, 4};  // instance k sits at z = 1 + order[k]
  for (const auto& blas : {tiles, cubes}) {
    std::vector<Instance> instances;
    for (uint32_t k = 0; k < 10; ++k) instances.push_back(translated(blas, 0, 0, 1.0f + float(order[k])));
    auto tlas = makeTlas(instances);
    ASSERT_TRUE(tlas);
    const bool boxesHere = blas == cubes;
    auto zOf = [&](uint32_t instance) { return 1.0f + float(order[instance]); };
    // The intersection shader commits where the ray enters the box (its bottom face, 0.25 below the instance's z).
    auto enter = [&](ProceduralCandidate& c) {
      const float t = zOf(c.info().instanceIndex) - 0.25f + 1.0f;
      if (t >= c.tMin() && t <= c.tMax()) c.commit(t, 1, false);
    };
    const Ray ray = rayFrom(2.3f, 1.6f, -1, 0, 0, 1);
    // The nearest two are ignored by the any-hit shader: the third nearest (z = 3) is the closest hit.
    Recorder ignoring;
    ignoring.onAnyHit = [&](const HitInfo& h) {
      return zOf(h.instanceIndex) < 2.5f ? AnyHitResult::Ignore : AnyHitResult::Accept;
    };
    ignoring.onIntersect = [&](ProceduralCandidate& c) {
      if (zOf(c.info().instanceIndex) > 2.5f) enter(c);
    };
    Traced t = traceOnce(*tlas, ray, ignoring);
    ASSERT_TRUE(t.hit);
    EXPECT_EQ(zOf(t.info.instanceIndex), 3.0f);
    EXPECT_TRUE(nearHit(t.info.t, boxesHere ? 3.75f : 4.0f, 10));
    // Every instance's candidate was seen at most once, and the nearest three at least.
    size_t calls = boxesHere ? ignoring.boxes.size() : ignoring.anyHits.size();
    EXPECT_GE(calls, 3u);
    EXPECT_LE(calls, 10u);
    // The first accepted candidate that terminates is the hit, wherever it lies.
    Recorder terminating;
    terminating.onAnyHit = [](const HitInfo&) { return AnyHitResult::AcceptAndTerminate; };
    terminating.onIntersect = [&](ProceduralCandidate& c) {
      const float tc = zOf(c.info().instanceIndex) - 0.25f + 1.0f;
      if (tc >= c.tMin() && tc <= c.tMax()) c.commit(tc, 1, true);
    };
    t = traceOnce(*tlas, ray, terminating);
    ASSERT_TRUE(t.hit);
    calls = boxesHere ? terminating.boxes.size() : terminating.anyHits.size();
    ASSERT_EQ(calls, 1u);
    const uint32_t first = boxesHere ? terminating.boxes[0].instanceIndex : terminating.anyHits[0].instanceIndex;
    EXPECT_EQ(t.info.instanceIndex, first);
    EXPECT_TRUE(nearHit(t.info.t, zOf(first) + (boxesHere ? 0.75f : 1.0f), 10));
    // An occlusion ray (TerminateOnFirstHit) ends at its first accepted candidate too.
    Recorder shadow;
    shadow.onIntersect = enter;
    Ray occ = ray;
    occ.flags = kRayTerminateOnFirstHit;
    EXPECT_TRUE(traceOnce(*tlas, occ, shadow).hit);
    EXPECT_EQ(boxesHere ? shadow.boxes.size() : shadow.anyHits.size(), 1u);
  }
}

TEST(AccelInstanceHierarchy, OneInstanceIsALeafAndNoneIsEmpty) {
  const std::shared_ptr<const Blas> big = makeBlas({tile(5, 4)});
  auto one = makeTlas({instanceOf(big)});
  ASSERT_TRUE(one);
  EXPECT_TRUE(one->impl().nodes.empty());
  EXPECT_TRUE(one->impl().root & detail::kLeafRef);
  const Traced t = traceOnce(*one, rayFrom(2.3f, 1.6f, -1, 0, 0, 1));
  EXPECT_TRUE(t.hit);
  EXPECT_EQ(t.info.primitiveIndex, 2u * (1 * 5 + 2) + 1);
  auto none = makeTlas({instanceOf(nullptr), instanceOf(big, 0, 0)});
  ASSERT_TRUE(none);
  EXPECT_EQ(none->impl().root, detail::kEmptyRef);
  EXPECT_FALSE(traceOnce(*none, rayFrom(2.3f, 1.6f, -1, 0, 0, 1)).hit);
}

// An instance stretched past the 1e18 the hierarchy's builder takes (Embree's binning asserted on bounds like
// those of vkrt_fuzz_accel_build's input, kept in fuzz/corpus/accel_build): the builder sees its bounds clamped, the
// node boxes that reach the clamp are unbounded on that side (conservative), and it is hit where a ray Embree can
// trace meets it, as are the instances beside it, also beside one translated past Embree's range.
TEST(AccelInstanceHierarchy, InstancesPastTheBuildersRangeAreClampedAndStillHit) {
  const std::shared_ptr<const Blas> blases[2] = {makeBlas({tile(5, 4)}), makeBlas({tile(2, 2)})};
  for (const BuildOptions& options : {BuildOptions{}, BuildOptions{.preferFastBuild = true}}) {
    std::vector<Instance> instances = {placed({.tile = 0, .x = 100, .y = 100, .z = 5}, blases),
                                       placed({.tile = 0, .x = -100, .y = 100, .z = 7}, blases)};
    Instance stretched = instances[0];
    const float m[3][4] = {{1e18f, 0, 0, 0}, {0, 1, 0, 200}, {0, 0, 1, 9}};  // x in [0, 5e18]
    std::memcpy(stretched.transform, m, sizeof m);
    instances.push_back(stretched);
    // Translated past 2^60: rays reach its space beyond Embree's range, so they skip it (and only it: every ray
    // through the top level missed while the range was checked over all instances at once).
    instances.push_back(placed({.tile = 0, .z = 4e18f}, blases));
    auto tlas = makeTlas(std::move(instances), options);
    ASSERT_TRUE(tlas);
    ASSERT_FALSE(tlas->impl().nodes.empty());
    bool unbounded = false;
    for (const detail::BvhNode& n : tlas->impl().nodes)
      for (int k = 0; k < 2; ++k) {
        unbounded |= n.upper[k][0] == HUGE_VALF;
        for (int d = 0; d < 3; ++d) EXPECT_FALSE(std::isnan(n.lower[k][d]) || std::isnan(n.upper[k][d]));
      }
    EXPECT_TRUE(unbounded);
    // (x, y) -> instance, t; each ray meets quad (0 or 2, 1) of its tile below the diagonal.
    for (const auto& [x, y, instance, primitive, t] :
         {std::tuple{102.55f, 101.5f, 0u, 14u, 6.0f}, std::tuple{-97.45f, 101.5f, 1u, 14u, 8.0f},
          std::tuple{5.5e17f, 201.5f, 2u, 10u, 10.0f}}) {
      const Traced hit = traceOnce(*tlas, rayFrom(x, y, -1, 0, 0, 1));
      ASSERT_TRUE(hit.hit) << x;
      EXPECT_EQ(hit.info.instanceIndex, instance) << x;
      EXPECT_EQ(hit.info.primitiveIndex, primitive) << x;
      EXPECT_FLOAT_EQ(hit.info.t, t) << x;
    }
  }
}

}  // namespace
}  // namespace vkrt::accel::test
