// Updates: a new structure with the new positions, the old one untouched, even while it is being traversed.
#include <atomic>
#include <thread>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

BuildOptions updatable() {
  BuildOptions o;
  o.allowUpdate = true;
  return o;
}

float hitT(const Tlas& tlas, const Ray& ray = rayUp()) {
  Traced r = traceOnce(tlas, ray);
  return r.hit ? r.info.t : -1.0f;
}

TEST(AccelUpdate, MovesTheHitsAndLeavesTheOriginalUnchanged) {
  auto original = makeBlas({quad(5), boxes({{-1, -1, 8, 1, 1, 9}})}, updatable());
  std::string error;
  auto moved = original->update({quad(7), boxes({{-1, -1, 3, 1, 1, 4}})}, &error);
  ASSERT_TRUE(moved) << error;
  EXPECT_TRUE(moved->options().allowUpdate);
  auto before = makeTlas({instanceOf(original)});
  auto after = makeTlas({instanceOf(moved)});
  EXPECT_NEAR(hitT(*before), 5.0f, kTol);
  EXPECT_NEAR(hitT(*after), 7.0f, kTol);
  // The boxes moved too: the intersection shader runs for the box at 3..4 within t <= 5 after the update, and
  // for the one at 8..9 within t >= 6 before it.
  Recorder rec;
  Ray nearOnly = rayUp(kRaySkipTriangles);
  nearOnly.tMax = 5;
  Ray farOnly = rayUp(kRaySkipTriangles);
  farOnly.tMin = 6;
  traceOnce(*after, nearOnly, rec);
  EXPECT_EQ(rec.boxes.size(), 1u);
  traceOnce(*before, nearOnly, rec);
  EXPECT_EQ(rec.boxes.size(), 1u);
  traceOnce(*after, farOnly, rec);
  EXPECT_EQ(rec.boxes.size(), 1u);
  traceOnce(*before, farOnly, rec);
  EXPECT_EQ(rec.boxes.size(), 2u);
  // The quads' extent changed with the positions: a ray beside the old quad meets the new, larger one.
  auto wide = original->update({quad(6, kGeometryOpaque, 3.0f), boxes({{-1, -1, 8, 1, 1, 9}})}, &error);
  ASSERT_TRUE(wide) << error;
  auto wideTlas = makeTlas({instanceOf(wide)});
  EXPECT_NEAR(hitT(*wideTlas, rayUp(0, 2.5f, 2.5f)), 6.0f, kTol);
  EXPECT_EQ(hitT(*before, rayUp(0, 2.5f, 2.5f)), -1.0f);
}

TEST(AccelUpdate, ChainsOfUpdatesReuseScenesWithoutMixingThemUp) {
  // Each update takes an idle scene of the family when one is left by a dead Blas; results must follow the
  // latest positions whichever scene they landed in.
  auto blas = makeBlas({quads({5, 10})}, updatable());
  std::string error;
  std::vector<std::shared_ptr<Blas>> alive{blas};
  for (int step = 1; step <= 12; ++step) {
    // The quads move up and grow: a refitted hierarchy must take the new extent too.
    const float z = 5.0f + 0.25f * step, half = 1.0f + 0.1f * step;
    auto next = alive.back()->update({quads({z, 10}, kGeometryOpaque, half)}, &error);
    ASSERT_TRUE(next) << error;
    if (step % 3 == 0) alive.erase(alive.begin());  // let some die: their scenes go idle
    alive.push_back(next);
    auto tlas = makeTlas({instanceOf(next)});
    EXPECT_NEAR(hitT(*tlas), z, kTol) << step;
    EXPECT_NEAR(hitT(*tlas, rayUp(0, half - 0.05f, half - 0.07f)), z, kTol) << step;
    for (size_t i = 0; i + 1 < alive.size(); ++i) {
      const float zi = alive[i]->geometries()[0].triangles.vertices[2];
      EXPECT_NEAR(hitT(*makeTlas({instanceOf(alive[i])})), zi, kTol) << step << " " << i;
    }
  }
}

TEST(AccelUpdate, RefitsWithEveryOtherOption) {
  // allowUpdate with lowMemory (Embree's compact layout) and with the other options, through refits.
  for (int variant = 0; variant < 3; ++variant) {
    BuildOptions o = updatable();
    o.lowMemory = variant == 0;
    o.preferFastBuild = variant == 1;
    o.preferFastTrace = variant == 2;
    auto first = makeBlas({quads({5, 10}), boxes({{-1, -1, 20, 1, 1, 21}})}, o);
    std::string error;
    std::shared_ptr<Blas> last = std::move(first);
    for (int step = 1; step <= 3; ++step) {
      auto next = last->update({quads({5.0f + step, 10}), boxes({{-1, -1, 20, 1, 1, 21}})}, &error);
      ASSERT_TRUE(next) << error;
      last = next;  // the previous one dies here and leaves its scene idle: steps 2 and 3 refit
      EXPECT_NEAR(hitT(*makeTlas({instanceOf(last)})), 5.0f + step, kTol) << variant << " " << step;
      EXPECT_EQ(last->options().lowMemory, o.lowMemory);
    }
  }
}

TEST(AccelUpdate, DifferentTopologyOrNoAllowUpdateBuildsAnew) {
  std::string error;
  auto fixed = makeBlas({quad(5)});  // no allowUpdate: update still gives the right structure
  auto a = fixed->update({quad(6)}, &error);
  ASSERT_TRUE(a) << error;
  EXPECT_NEAR(hitT(*makeTlas({instanceOf(a)})), 6.0f, kTol);
  auto updatableBlas = makeBlas({quad(5)}, updatable());
  Geometry more = quads({6, 8});  // more primitives than the original
  auto b = updatableBlas->update({more}, &error);
  ASSERT_TRUE(b) << error;
  EXPECT_NEAR(hitT(*makeTlas({instanceOf(b)})), 6.0f, kTol);
  Geometry inactive = quad(7);
  inactive.triangles.vertices[0] = NAN;  // a primitive turned inactive
  auto c = updatableBlas->update({inactive}, &error);
  ASSERT_TRUE(c) << error;
  Traced r = traceOnce(*makeTlas({instanceOf(c)}), rayUp(0, -0.5f, 0.6f));
  EXPECT_FALSE(r.hit);  // the second triangle shares vertex 0
  EXPECT_NEAR(hitT(*makeTlas({instanceOf(updatableBlas)})), 5.0f, kTol);
}

TEST(AccelUpdate, TlasUpdateMovesInstancesAndLeavesTheOriginal) {
  auto blas = makeBlas({quad(5)});
  auto tlas = makeTlas({instanceOf(blas), translated(blas, 10, 0, 0)}, updatable());
  std::string error;
  auto moved = tlas->update({translated(blas, 0, 0, 3), instanceOf(nullptr)}, &error);
  ASSERT_TRUE(moved) << error;
  EXPECT_NEAR(hitT(*tlas), 5.0f, kTol);
  EXPECT_NEAR(hitT(*tlas, rayUp(0, 10.3f, -0.4f)), 5.0f, kTol);
  EXPECT_NEAR(hitT(*moved), 8.0f, kTol);
  EXPECT_EQ(hitT(*moved, rayUp(0, 10.3f, -0.4f)), -1.0f);
  EXPECT_TRUE(moved->options().allowUpdate);
}

TEST(AccelUpdate, OriginalIsTraversedUndisturbedDuringUpdates) {
  auto blas = makeBlas({quads({5, 9}, 0)}, updatable());
  auto tlas = makeTlas({instanceOf(blas)});
  std::atomic<bool> stop{false};
  std::atomic<int> wrong{0}, traced{0};
  std::thread reader([&] {
    while (!stop.load()) {
      Recorder rec;  // non-opaque: the filter and the handler run too
      Traced r = traceOnce(*tlas, rayUp(), rec);
      if (!r.hit || std::abs(r.info.t - 5.0f) > kTol) wrong++;
      traced++;
    }
  });
  std::string error;
  std::shared_ptr<Blas> last = blas;
  for (int i = 0; i < 30; ++i) {
    auto next = last->update({quads({6.0f + 0.1f * i, 9}, 0)}, &error);
    ASSERT_TRUE(next) << error;
    EXPECT_NEAR(hitT(*makeTlas({instanceOf(next)})), 6.0f + 0.1f * i, kTol);
    last = next;
  }
  while (traced.load() < 100) std::this_thread::yield();
  stop = true;
  reader.join();
  EXPECT_EQ(wrong.load(), 0);
}

}  // namespace
}  // namespace vkrt::accel::test
