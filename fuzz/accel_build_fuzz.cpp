// libFuzzer target: acceleration structure build inputs (src/accel), as the runtime hands them over from
// vkCmdBuildAccelerationStructuresKHR and friends after its checks: any vertex, index and box data (NaN, infinity,
// huge values, indices past the vertices, degenerate and inverted boxes), any geometry and instance flags, masks,
// SBT offsets and transforms, every build option; then an update, a top level over the result, rays through it
// (any origin, direction, interval, ray flags and cull mask; any-hit and intersection answers from the input),
// and a serialize/deserialize round trip of both levels. Builds may fail with an error; nothing may crash, read
// out of bounds or leak. The input is decoded with libFuzzer's FuzzedDataProvider (any bytes are an input).
#include <fuzzer/FuzzedDataProvider.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "accel/accel.hpp"

namespace {

using namespace vkrt::accel;

// A coordinate: mostly small integers and halves (so that geometry meets rays), sometimes any bits.
float coordinate(FuzzedDataProvider& p) {
  uint8_t k = p.ConsumeIntegral<uint8_t>();
  if (k < 200) return float(int(k % 17) - 8) * 0.5f;
  return std::bit_cast<float>(p.ConsumeIntegral<uint32_t>());
}

uint32_t anyOrSmall(FuzzedDataProvider& p, uint32_t small) {
  return p.ConsumeBool() ? p.ConsumeIntegralInRange<uint32_t>(0, small) : p.ConsumeIntegral<uint32_t>();
}

std::vector<Geometry> geometries(FuzzedDataProvider& p) {
  std::vector<Geometry> out(p.ConsumeIntegralInRange<size_t>(0, 3));
  for (Geometry& g : out) {
    if (p.ConsumeBool()) {
      g.kind = Geometry::Aabbs;
      g.aabbs.flags = anyOrSmall(p, 3);
      size_t n = 6 * p.ConsumeIntegralInRange<size_t>(0, 6);
      for (size_t i = 0; i < n; ++i) g.aabbs.boxes.push_back(coordinate(p));
    } else {
      g.triangles.flags = anyOrSmall(p, 3);
      size_t v = p.ConsumeIntegralInRange<size_t>(0, 12);
      for (size_t i = 0; i < 3 * v; ++i) g.triangles.vertices.push_back(coordinate(p));
      size_t n = 3 * p.ConsumeIntegralInRange<size_t>(0, 8);
      for (size_t i = 0; i < n; ++i) g.triangles.indices.push_back(anyOrSmall(p, uint32_t(v)));
    }
  }
  return out;
}

BuildOptions options(FuzzedDataProvider& p) {
  BuildOptions o;
  o.preferFastTrace = p.ConsumeBool();
  o.preferFastBuild = p.ConsumeBool();
  o.allowUpdate = p.ConsumeBool();
  o.lowMemory = p.ConsumeBool();
  return o;
}

class Handler : public HitHandler {
 public:
  explicit Handler(FuzzedDataProvider& p) : p_(p) {}
  AnyHitResult anyHit(const HitInfo&) override {
    switch (p_.ConsumeIntegralInRange<int>(0, 2)) {
      case 0: return AnyHitResult::Accept;
      case 1: return AnyHitResult::Ignore;
      default: return AnyHitResult::AcceptAndTerminate;
    }
  }
  void intersect(ProceduralCandidate& c) override {
    (void)c.info();
    (void)c.opaque();
    if (!p_.ConsumeBool()) return;
    float t = p_.ConsumeBool() ? c.tMin() + (c.tMax() - c.tMin()) * 0.5f : coordinate(p_);
    c.commit(t, p_.ConsumeIntegral<uint8_t>(), p_.ConsumeBool());
  }

 private:
  FuzzedDataProvider& p_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzedDataProvider p(data, size);
  std::string error;
  std::shared_ptr<const Blas> blas = Blas::build(geometries(p), options(p), &error);
  if (blas && p.ConsumeBool()) {
    // An update: the same geometries with the vertices and boxes moved, or (breaking the rules) others.
    std::vector<Geometry> moved = blas->geometries();
    if (p.ConsumeBool()) {
      for (Geometry& g : moved) {
        for (float& f : g.triangles.vertices) f = p.ConsumeBool() ? f : coordinate(p);
        for (float& f : g.aabbs.boxes) f = p.ConsumeBool() ? f : coordinate(p);
      }
    } else {
      moved = geometries(p);
    }
    if (std::shared_ptr<const Blas> updated = blas->update(std::move(moved), &error)) blas = updated;
  }
  if (blas) {
    std::vector<uint8_t> bytes = serialize(*blas);
    std::shared_ptr<Blas> again = deserializeBlas(bytes.data(), bytes.size(), &error);
    if (!again || again->primitiveCount() != blas->primitiveCount()) __builtin_trap();
  }
  std::vector<Instance> instances(p.ConsumeIntegralInRange<size_t>(0, 4));
  for (Instance& in : instances) {
    for (auto& row : in.transform)
      for (float& f : row) f = p.ConsumeBool() ? f : coordinate(p);
    in.customIndex = anyOrSmall(p, 4);
    in.mask = anyOrSmall(p, 0xff);
    in.sbtOffset = anyOrSmall(p, 4);
    in.flags = anyOrSmall(p, 15);
    if (p.ConsumeIntegralInRange<int>(0, 3)) in.blas = blas.get();
  }
  std::shared_ptr<const Tlas> tlas = Tlas::build(std::move(instances), options(p), &error);
  if (!tlas) return 0;
  if (p.ConsumeBool()) {
    std::vector<const Blas*> refs;
    std::vector<uint8_t> bytes = serialize(*tlas, &refs);
    std::vector<std::shared_ptr<const Blas>> resolved;
    for (const Blas* b : refs) resolved.push_back(b ? blas : nullptr);
    if (!deserializeTlas(bytes.data(), bytes.size(), resolved, &error)) __builtin_trap();
  }
  Handler handler(p);
  for (int i = p.ConsumeIntegralInRange<int>(0, 8); i > 0; --i) {
    Ray ray;
    for (float& f : ray.origin) f = coordinate(p);
    for (float& f : ray.direction) f = coordinate(p);
    ray.tMin = p.ConsumeBool() ? 0.0f : coordinate(p);
    ray.tMax = p.ConsumeBool() ? 1e30f : coordinate(p);
    ray.flags = anyOrSmall(p, 0x3ff);
    ray.cullMask = anyOrSmall(p, 0xff);
    HitInfo hit;
    (void)trace(*tlas, ray, handler, &hit);
  }
  return 0;
}
