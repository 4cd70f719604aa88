// Builds: inactive primitives and instances, input validation, build options, what a structure reports of itself.
#include <cmath>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// `n` quads at z = 5 side by side (x in [-3,-1], [-1,1], [1,3], ...; quad q is primitives 2q and 2q + 1, on
// vertices 4q to 4q + 3).
Geometry row(int n = 3) {
  Geometry g;
  g.kind = Geometry::Triangles;
  g.triangles.flags = kGeometryOpaque;
  for (int q = 0; q < n; ++q) addQuad(g.triangles, -3.0f + 2 * q, -1, -1.0f + 2 * q, 1, 5);
  return g;
}

// Rays at the first triangle (below the diagonal) of each quad.
Ray atQuad(int q) { return rayUp(0, -2.0f + 2.0f * q + 0.3f, -0.4f); }

// An Instance does not own its Blas; the Tlas built over it holds each distinct one (its instances() keep pointing
// at them): the caller's Blases dropped after the build are still traced, and they die with the Tlas.
TEST(AccelOwnership, ATlasHoldsItsInstancesBlasesUntilItDies) {
  std::weak_ptr<Blas> first, second;
  std::shared_ptr<Tlas> tlas;
  {
    auto a = makeBlas({row(1)}), b = makeBlas({row(3)});
    first = a, second = b;
    // Runs of each and a repeat after the other (a, a, b, a, inactive).
    tlas = makeTlas({instanceOf(a), instanceOf(a), translated(b, 0, 0, 1), instanceOf(a), instanceOf(nullptr)});
  }
  EXPECT_FALSE(first.expired());
  EXPECT_FALSE(second.expired());
  EXPECT_EQ(tlas->instances()[2].blas, second.lock().get());
  EXPECT_EQ(tlas->instances()[4].blas, nullptr);
  Traced r = traceOnce(*tlas, atQuad(2));  // b's third quad, at z = 6 (only b has one there)
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.instanceIndex, 2u);
  EXPECT_FLOAT_EQ(r.info.t, 6.0f);
  tlas.reset();
  EXPECT_TRUE(first.expired());
  EXPECT_TRUE(second.expired());
}

TEST(AccelInactive, TrianglesWithANaNXAreNeverHitAndKeepTheOthersIndices) {
  // "An inactive triangle is one for which the first (X) component of any vertex is NaN". Quad q's triangles
  // are (4q, 4q+1, 4q+2) and (4q, 4q+2, 4q+3).
  Geometry g = row(4);
  g.triangles.vertices[3 * 1] = NAN;   // quad 0: the second vertex of its first triangle only
  g.triangles.vertices[3 * 6] = NAN;   // quad 1: the third vertex of its first triangle, second of its second
  g.triangles.vertices[3 * 12] = NAN;  // quad 3: the first vertex of both
  auto tlas = sceneOf({g});
  EXPECT_FALSE(traceOnce(*tlas, atQuad(0)).hit);
  EXPECT_FALSE(traceOnce(*tlas, atQuad(1)).hit);
  EXPECT_FALSE(traceOnce(*tlas, rayUp(0, -0.5f, 0.6f)).hit);
  EXPECT_FALSE(traceOnce(*tlas, atQuad(3)).hit);
  EXPECT_FALSE(traceOnce(*tlas, rayUp(0, 3.5f, 0.6f)).hit);
  Traced r = traceOnce(*tlas, rayUp(0, -2.5f, 0.6f));  // quad 0's second triangle stays
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 1u);
  r = traceOnce(*tlas, atQuad(2));
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 4u);
  EXPECT_EQ(tlas->instances()[0].blas->primitiveCount(), 8u);  // inactive ones count
  // Any-hit shaders never see an inactive one either.
  Geometry n = g;
  n.triangles.flags = 0;
  auto noOpaque = sceneOf({n});
  Recorder rec;
  EXPECT_FALSE(traceOnce(*noOpaque, atQuad(0), rec).hit);
  EXPECT_FALSE(traceOnce(*noOpaque, atQuad(3), rec).hit);
  EXPECT_TRUE(rec.anyHits.empty());
}

TEST(AccelInactive, BoxesWithANaNMinXAreNeverIntersected) {
  auto tlas = sceneOf({boxes({{NAN, -1, 4, 1, 1, 6}, {-1, -1, 8, 1, 1, 9}})});
  Recorder rec;
  rec.onIntersect = [](ProceduralCandidate& c) { c.commit(c.info().primitiveIndex ? 8.5f : 4.5f, 1, false); };
  Traced r = traceOnce(*tlas, rayUp(), rec);
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 1u);
  EXPECT_EQ(r.info.t, 8.5f);
  ASSERT_EQ(rec.boxes.size(), 1u);
  EXPECT_EQ(rec.boxes[0].primitiveIndex, 1u);
}

TEST(AccelInactive, InstancesWithoutABlasOrAnInverseAreNeverHitAndKeepTheOthersIndices) {
  auto blas = makeBlas({quad(5)});
  Instance singular = instanceOf(blas);
  singular.transform[2][2] = 0;  // flattens z: no inverse
  Instance zero = instanceOf(blas);
  for (auto& r : zero.transform)
    for (float& v : r) v = 0;
  auto tlas = makeTlas({instanceOf(nullptr), singular, zero, translated(blas, 0, 0, 2), instanceOf(nullptr)});
  Traced r = traceOnce(*tlas, rayUp());
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.instanceIndex, 3u);
  EXPECT_NEAR(r.info.t, 7.0f, kTol);
  EXPECT_EQ(tlas->instances().size(), 5u);
  auto none = makeTlas({instanceOf(nullptr), instanceOf(nullptr)});
  EXPECT_FALSE(traceOnce(*none, rayUp()).hit);
}

TEST(AccelBuild, MalformedInputIsRefusedWithAnError) {
  std::string error;
  Geometry g = quad(5);
  g.triangles.vertices.pop_back();
  EXPECT_FALSE(Blas::build({g}, {}, &error));
  EXPECT_NE(error.find("geometry 0"), std::string::npos) << error;
  g = quad(5);
  g.triangles.indices.pop_back();
  error.clear();
  EXPECT_FALSE(Blas::build({quad(1), g}, {}, &error));
  EXPECT_NE(error.find("geometry 1"), std::string::npos) << error;
  Geometry b = boxes({{-1, -1, 4, 1, 1, 6}});
  b.aabbs.boxes.pop_back();
  error.clear();
  EXPECT_FALSE(Blas::build({b}, {}, &error));
  EXPECT_FALSE(error.empty());
  // A Blas that fails to build leaves the caller nothing to update either.
  auto ok = makeBlas({quad(5)});
  error.clear();
  EXPECT_FALSE(ok->update({g}, &error));
  EXPECT_FALSE(error.empty());
}

TEST(AccelBuild, OutOfRangeIndicesAreNeverHit) {
  Geometry g = row();
  g.triangles.indices[0] = 1000;  // quad 0's first triangle
  auto tlas = sceneOf({g});
  EXPECT_FALSE(traceOnce(*tlas, atQuad(0)).hit);
  Traced r = traceOnce(*tlas, atQuad(1));
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 2u);
}

TEST(AccelBuild, EveryOptionBuildsTheSameScene) {
  // The build options change how Embree builds, never what is hit.
  std::vector<BuildOptions> all(5);
  all[1].preferFastTrace = true;
  all[2].preferFastBuild = true;
  all[3].allowUpdate = true;
  all[4].lowMemory = true;
  for (size_t i = 0; i < all.size(); ++i) {
    auto blas = makeBlas({row(), quads({2}, 0), boxes({{-3, -1, 7, 3, 1, 8}})}, all[i]);
    ASSERT_TRUE(blas);
    EXPECT_EQ(blas->options().preferFastTrace, all[i].preferFastTrace);
    EXPECT_EQ(blas->options().lowMemory, all[i].lowMemory);
    EXPECT_EQ(blas->primitiveCount(), 6u + 2u + 1u);
    EXPECT_GT(blas->nativeBytes(), 9u * 64u);
    auto tlas = makeTlas({instanceOf(blas)}, all[i]);
    for (int q = 0; q < 3; ++q) {
      Recorder rec;
      rec.onAnyHit = [](const HitInfo&) { return AnyHitResult::Ignore; };
      Traced r = traceOnce(*tlas, atQuad(q), rec);
      ASSERT_TRUE(r.hit) << i << " " << q;
      EXPECT_NEAR(r.info.t, 5.0f, kTol);
      EXPECT_EQ(r.info.primitiveIndex, 2u * q);
      EXPECT_EQ(rec.anyHits.size(), q == 1 ? 1u : 0u);  // the non-opaque quad at 2 spans x in [-1, 1]
    }
    EXPECT_GT(tlas->nativeBytes(), 0u);
    EXPECT_EQ(tlas->options().allowUpdate, all[i].allowUpdate);
  }
}

TEST(AccelBuild, KeepsItsOwnCopiesOfTheInputs) {
  std::shared_ptr<Tlas> tlas;
  {
    std::vector<Geometry> geometries{row()};
    auto blas = makeBlas(geometries);  // a copy is passed in; the original is destroyed below
    geometries.clear();
    geometries.shrink_to_fit();
    tlas = makeTlas({instanceOf(blas)});
  }  // the only reference to the Blas is the Tlas's now
  Traced r = traceOnce(*tlas, atQuad(2));
  ASSERT_TRUE(r.hit);
  EXPECT_EQ(r.info.primitiveIndex, 4u);
  const auto& kept = tlas->instances()[0].blas->geometries();
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].triangles.vertices.size(), 12u * 3u);
  EXPECT_EQ(kept[0].triangles.indices.size(), 18u);
}

}  // namespace
}  // namespace vkrt::accel::test
