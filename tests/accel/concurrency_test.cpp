// Many threads tracing one Tlas at once see what one thread sees.
#include <random>
#include <thread>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

struct Result {
  bool hit = false;
  float t = 0;
  uint32_t instance = 0, primitive = 0, hitKind = 0;
  size_t anyHits = 0, boxes = 0;
  bool operator==(const Result&) const = default;
};

TEST(AccelConcurrency, ManyThreadsTraceOneTlasLikeOne) {
  // Opaque and non-opaque triangles and boxes, in instances: the filter, the box callbacks and the handler all
  // run on every thread.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  Geometry soup;
  soup.kind = Geometry::Triangles;
  for (int i = 0; i < 3000; ++i) {
    const float c[3] = {4 * u(rng), 4 * u(rng), 4 + 3 * u(rng)};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) soup.triangles.vertices.push_back(c[j] + 0.4f * u(rng));
    for (uint32_t k = 0; k < 3; ++k) soup.triangles.indices.push_back(uint32_t(3 * i) + k);
  }
  Geometry opaqueSoup = soup;
  opaqueSoup.triangles.flags = kGeometryOpaque;
  std::vector<std::array<float, 6>> list;
  for (int i = 0; i < 200; ++i) {
    const float x = 4 * u(rng), y = 4 * u(rng), z = 4 + 3 * u(rng);
    list.push_back({x, y, z, x + 0.3f, y + 0.3f, z + 0.3f});
  }
  auto blas = makeBlas({soup, boxes(list, 0)});
  auto opaqueBlas = makeBlas({opaqueSoup});
  auto tlas = makeTlas({instanceOf(blas), translated(opaqueBlas, 0.5f, 0.5f, 1), translated(blas, -0.5f, 0, 2)});

  std::vector<Ray> rays;
  for (int i = 0; i < 4000; ++i) {
    Ray r = rayFrom(4 * u(rng), 4 * u(rng), -2, 0.3f * u(rng), 0.3f * u(rng), 1, 0, 50);
    r.flags = std::vector<uint32_t>{0, kRayCullBackFacingTriangles, kRayOpaque, kRayTerminateOnFirstHit, 0}[i % 5];
    rays.push_back(r);
  }
  // A handler that depends on nothing but the candidate (deterministic whatever thread runs it).
  auto traceAll = [&](size_t begin, size_t step, std::vector<Result>& out) {
    for (size_t i = begin; i < rays.size(); i += step) {
      Recorder rec;
      rec.onAnyHit = [](const HitInfo& h) {
        return h.primitiveIndex % 3 == 0 ? AnyHitResult::Ignore : AnyHitResult::Accept;
      };
      rec.onIntersect = [](ProceduralCandidate& c) {
        const HitInfo& h = c.info();
        if (h.primitiveIndex % 2) return;
        const float t = c.tMin() + 5 + 0.001f * float(h.primitiveIndex);
        if (t <= c.tMax()) c.commit(t, h.primitiveIndex, false);
      };
      Traced r = traceOnce(*tlas, rays[i], rec);
      Result& res = out[i];
      res.hit = r.hit;
      if (r.hit) {
        res.t = r.info.t;
        res.instance = r.info.instanceIndex;
        res.primitive = r.info.primitiveIndex;
        res.hitKind = r.info.hitKind;
      }
      // Which candidates are met before the closest one depends on the hierarchy, not on the thread.
      res.anyHits = rec.anyHits.size();
      res.boxes = rec.boxes.size();
    }
  };
  std::vector<Result> single(rays.size()), multi(rays.size());
  traceAll(0, 1, single);
  const size_t threads = 8;
  std::vector<std::thread> pool;
  for (size_t t = 0; t < threads; ++t) pool.emplace_back([&, t] { traceAll(t, threads, multi); });
  for (auto& t : pool) t.join();
  size_t hits = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(single[i], multi[i]) << "ray " << i;
    hits += single[i].hit;
  }
  EXPECT_GT(hits, rays.size() / 3);
}

}  // namespace
}  // namespace vkrt::accel::test
