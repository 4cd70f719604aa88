// Serialization: a round trip traces identically; corrupt, truncated or foreign data is refused, never read past.
#include <cstring>
#include <random>

#include "accel/scenes.hpp"

namespace vkrt::accel::test {
namespace {

// A Blas with two triangle geometries (one non-opaque, one with an inactive triangle) and boxes, and a Tlas with
// several instances of it and of a second Blas, an inactive instance, flags, masks and transforms.
struct World {
  std::shared_ptr<Blas> a, b;
  std::shared_ptr<Tlas> tlas;
};

World makeWorld() {
  World w;
  Geometry withInactive = quads({3, 6});
  withInactive.triangles.vertices[3 * 5] = NAN;  // the second quad's second vertex
  BuildOptions fastTrace;
  fastTrace.preferFastTrace = true;
  w.a =
      makeBlas({withInactive, quads({4.5f}, 0, 0.5f), boxes({{-2, -2, 8, 2, 2, 9}, {NAN, 0, 0, 1, 1, 1}})}, fastTrace);
  w.b = makeBlas({quads({2, 7}, kGeometryOpaque | kGeometryNoDuplicateAnyHit, 3)});
  Instance i1 = translated(w.a, 1, 0, 0);
  i1.customIndex = 11;
  i1.sbtOffset = 5;
  i1.flags = kInstanceTriangleFlipFacing;
  Instance i2 = instanceOf(w.b, kInstanceForceNoOpaque, 0x0F);
  const float rot[3][4] = {{0, -1, 0, 20}, {1, 0, 0, 0}, {0, 0, 1, 1}};
  std::copy(&rot[0][0], &rot[0][0] + 12, &i2.transform[0][0]);
  Instance i3 = translated(w.a, -20, 0, 0);
  i3.transform[0][0] = -1;  // mirrored
  i3.mask = 0xF0;
  BuildOptions updatable;
  updatable.allowUpdate = true;
  w.tlas = makeTlas({instanceOf(nullptr), i1, i2, i3}, updatable);
  return w;
}

// A handler whose answers depend only on the candidate, not on the order of the traversal: Ignore every fourth
// primitive from the second, and commit a box's entry (Blas a's first box, [-2, 2]^2 x [8, 9] in object space).
struct Deterministic : Recorder {
  Deterministic() {
    onAnyHit = [](const HitInfo& h) { return h.primitiveIndex % 4 == 1 ? AnyHitResult::Ignore : AnyHitResult::Accept; };
    onIntersect = [](ProceduralCandidate& c) {
      const HitInfo& h = c.info();
      const float t = (8 - h.objectRayOrigin[2]) / h.objectRayDirection[2];
      if (t >= c.tMin() && t <= c.tMax()) c.commit(t, 0x20 + h.primitiveIndex, false);
    };
  }
};

std::vector<Ray> probeRays() {
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> x(-2.5f, 2.5f), d(-0.2f, 0.2f);
  const float centers[3] = {1, 20, -20};  // the instances' x
  std::vector<Ray> rays;
  for (int i = 0; i < 3000; ++i) {
    Ray r = rayFrom(centers[i % 3] + x(rng), x(rng), -1, d(rng), d(rng), 1, 0, 100);
    r.flags = std::vector<uint32_t>{0,
                                    kRayCullBackFacingTriangles,
                                    kRayNoOpaque,
                                    kRayOpaque,
                                    kRayCullOpaque,
                                    kRaySkipAabbs,
                                    kRayTerminateOnFirstHit}[i % 7];
    r.cullMask = i % 5 == 0 ? 0x0F : 0xFF;
    rays.push_back(r);
  }
  return rays;
}

void expectSameTraversal(const Tlas& x, const Tlas& y) {
  int hits = 0;
  for (const Ray& ray : probeRays()) {
    Deterministic hx, hy;
    Traced a = traceOnce(x, ray, hx);
    Traced b = traceOnce(y, ray, hy);
    ASSERT_EQ(a.hit, b.hit);
    if (!a.hit || (ray.flags & kRayTerminateOnFirstHit)) continue;  // (which hit comes first may differ)
    ++hits;
    EXPECT_EQ(a.info.t, b.info.t);
    EXPECT_EQ(a.info.instanceIndex, b.info.instanceIndex);
    EXPECT_EQ(a.info.geometryIndex, b.info.geometryIndex);
    EXPECT_EQ(a.info.primitiveIndex, b.info.primitiveIndex);
    EXPECT_EQ(a.info.customIndex, b.info.customIndex);
    EXPECT_EQ(a.info.sbtOffset, b.info.sbtOffset);
    EXPECT_EQ(a.info.hitKind, b.info.hitKind);
    EXPECT_EQ(a.info.barycentrics[0], b.info.barycentrics[0]);
    EXPECT_EQ(a.info.barycentrics[1], b.info.barycentrics[1]);
    EXPECT_EQ(std::memcmp(a.info.worldToObject, b.info.worldToObject, 12 * sizeof(float)), 0);
  }
  EXPECT_GT(hits, 500);
}

TEST(AccelSerialize, RoundTripTracesIdentically) {
  World w = makeWorld();
  std::string error;
  auto a = deserializeBlas(serialize(*w.a).data(), serialize(*w.a).size(), &error);
  ASSERT_TRUE(a) << error;
  auto bytesB = serialize(*w.b);
  auto b = deserializeBlas(bytesB.data(), bytesB.size(), &error);
  ASSERT_TRUE(b) << error;
  EXPECT_TRUE(a->options().preferFastTrace);
  EXPECT_EQ(a->primitiveCount(), w.a->primitiveCount());
  EXPECT_EQ(serialize(*a), serialize(*w.a));  // the inputs survive bit for bit (NaNs included)

  std::vector<const Blas*> refs;
  auto bytes = serialize(*w.tlas, &refs);
  // One reference per instance: none for the inactive one, a, b, a.
  ASSERT_EQ(refs.size(), 4u);
  EXPECT_EQ(refs[0], nullptr);
  EXPECT_EQ(refs[1], w.a.get());
  EXPECT_EQ(refs[2], w.b.get());
  EXPECT_EQ(refs[3], w.a.get());
  auto tlas = deserializeTlas(bytes.data(), bytes.size(), {nullptr, a, b, a}, &error);
  ASSERT_TRUE(tlas) << error;
  EXPECT_TRUE(tlas->options().allowUpdate);
  ASSERT_EQ(tlas->instances().size(), 4u);
  EXPECT_EQ(tlas->instances()[0].blas, nullptr);
  EXPECT_EQ(tlas->instances()[3].blas, a.get());
  expectSameTraversal(*w.tlas, *tlas);
  // The same bytes resolved against the original Blases trace the same too.
  auto again = deserializeTlas(bytes.data(), bytes.size(), {nullptr, w.a, w.b, w.a}, &error);
  ASSERT_TRUE(again) << error;
  expectSameTraversal(*w.tlas, *again);
}

TEST(AccelSerialize, EmptyStructuresRoundTrip) {
  std::string error;
  auto blas = makeBlas({});
  auto bytes = serialize(*blas);
  auto back = deserializeBlas(bytes.data(), bytes.size(), &error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->geometries().size(), 0u);
  std::vector<const Blas*> refs;
  auto tbytes = serialize(*makeTlas({}), &refs);
  EXPECT_TRUE(refs.empty());
  EXPECT_TRUE(deserializeTlas(tbytes.data(), tbytes.size(), {}, &error)) << error;
}

// Deserializes from a heap copy of exactly `size` bytes, so that AddressSanitizer catches a read past the end.
std::shared_ptr<Blas> blasFrom(const std::vector<uint8_t>& bytes, size_t size, std::string* error) {
  std::unique_ptr<uint8_t[]> copy(new uint8_t[size ? size : 1]);
  if (size) std::memcpy(copy.get(), bytes.data(), size);
  return deserializeBlas(copy.get(), size, error);
}

std::shared_ptr<Tlas> tlasFrom(const std::vector<uint8_t>& bytes, size_t size,
                               const std::vector<std::shared_ptr<const Blas>>& refs, std::string* error) {
  std::unique_ptr<uint8_t[]> copy(new uint8_t[size ? size : 1]);
  if (size) std::memcpy(copy.get(), bytes.data(), size);
  return deserializeTlas(copy.get(), size, refs, error);
}

TEST(AccelSerialize, TruncatedDataIsRefused) {
  World w = makeWorld();
  auto bytes = serialize(*w.a);
  for (size_t size = 0; size < bytes.size(); ++size) {
    std::string error;
    EXPECT_FALSE(blasFrom(bytes, size, &error)) << size;
    EXPECT_FALSE(error.empty()) << size;
  }
  std::vector<const Blas*> refs;
  auto tbytes = serialize(*w.tlas, &refs);
  for (size_t size = 0; size < tbytes.size(); ++size) {
    std::string error;
    EXPECT_FALSE(tlasFrom(tbytes, size, {nullptr, w.a, w.b, w.a}, &error)) << size;
    EXPECT_FALSE(error.empty()) << size;
  }
  // Trailing bytes are refused too.
  bytes.push_back(0);
  std::string error;
  EXPECT_FALSE(blasFrom(bytes, bytes.size(), &error));
  EXPECT_FALSE(deserializeBlas(nullptr, 0, &error));
}

TEST(AccelSerialize, CorruptDataIsRefused) {
  World w = makeWorld();
  const auto bytes = serialize(*w.a);
  // Every single-byte change anywhere (header fields, counts, floats, indices) is caught.
  for (size_t at = 0; at < bytes.size(); ++at) {
    auto bad = bytes;
    bad[at] ^= 0x5A;
    std::string error;
    EXPECT_FALSE(blasFrom(bad, bad.size(), &error)) << at;
    EXPECT_FALSE(error.empty()) << at;
  }
  // Random garbage of many sizes.
  std::mt19937 rng(5);
  for (int i = 0; i < 500; ++i) {
    std::vector<uint8_t> garbage(rng() % 300);
    for (auto& c : garbage) c = uint8_t(rng());
    std::string error;
    EXPECT_FALSE(blasFrom(garbage, garbage.size(), &error));
    EXPECT_FALSE(tlasFrom(garbage, garbage.size(), {w.a}, &error));
  }
}

TEST(AccelSerialize, ForeignOrMismatchedDataIsRefused) {
  World w = makeWorld();
  std::string error;
  std::vector<const Blas*> refs;
  auto tbytes = serialize(*w.tlas, &refs);
  auto bbytes = serialize(*w.a);
  EXPECT_FALSE(deserializeBlas(tbytes.data(), tbytes.size(), &error));  // a Tlas is not a Blas
  EXPECT_NE(error.find("bottom-level"), std::string::npos) << error;
  EXPECT_FALSE(deserializeTlas(bbytes.data(), bbytes.size(), {}, &error));
  EXPECT_FALSE(deserializeTlas(tbytes.data(), tbytes.size(), {w.a}, &error));  // one reference per instance: four
  EXPECT_NE(error.find("references 4"), std::string::npos) << error;
  // A Blas the runtime could not resolve (null) leaves its instance inactive.
  auto partial = deserializeTlas(tbytes.data(), tbytes.size(), {nullptr, w.a, nullptr, w.a}, &error);
  ASSERT_TRUE(partial) << error;
  EXPECT_EQ(partial->instances()[2].blas, nullptr);
  EXPECT_TRUE(partial->instances()[1].blas);
}

// The format comment in serialize.cpp documents the checksum; with it, data that is structurally wrong but
// correctly checksummed can be made, to reach the structural checks behind the checksum.
uint64_t documentedChecksum(const uint8_t* p, size_t n) {
  uint64_t h = 0x9E3779B97F4A7C15ull ^ n;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = (h ^ w) * 0x100000001B3ull;
    h ^= h >> 29;
  }
  for (; i < n; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
  return h ^ (h >> 32);
}

void reseal(std::vector<uint8_t>& bytes) {
  const uint64_t sum = documentedChecksum(bytes.data() + 32, bytes.size() - 32);
  std::memcpy(bytes.data() + 24, &sum, 8);
}

template <typename T>
void poke(std::vector<uint8_t>& bytes, size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
  reseal(bytes);
}

TEST(AccelSerialize, StructurallyWrongButChecksummedDataIsRefused) {
  World w = makeWorld();
  const auto bytes = serialize(*w.a);
  std::string error;
  {
    auto ok = bytes;
    reseal(ok);  // resealing unchanged data changes nothing: the documented checksum is the one in use
    ASSERT_TRUE(blasFrom(ok, ok.size(), &error)) << error;
  }
  // Payload: u32 geometry count at 32; geometry headers (24 bytes each) from 40: kind, flags, floats, indices.
  struct Case {
    size_t at;
    uint64_t value;
    int bytes;
    const char* what;
  } cases[] = {
      {32, 0xFFFFFFFFull, 4, "geometry count"},
      {32, 4, 4, "one geometry more"},
      {32, 2, 4, "one geometry less"},
      {40, 7, 4, "geometry kind"},
      {48, 1ull << 60, 8, "huge float count"},
      {48, 3 * 7, 8, "float count not matching the data"},
      {48, 3 * 8 + 1, 8, "vertex floats not a multiple of 3"},
      {48, 3 * (1ull << 58), 8, "huge float count, a multiple of 3"},
      {48, 3 * 9, 8, "one vertex more than the data holds"},
      {96, 6 * 3, 8, "one box more than the data holds"},
      {56, 1ull << 62, 8, "huge index count"},
      {56, 13, 8, "indices not a multiple of 3"},
      {40 + 2 * 24 + 8, 6 * 3 - 1, 8, "box floats not a multiple of 6"},
      {40 + 2 * 24 + 16, 3, 8, "indices on boxes"},
      {4, 2, 4, "version"},
      {8, 2, 4, "kind"},
      {12, 0x100, 4, "unknown option bits"},
      {16, 12345, 8, "payload size"},
  };
  for (const Case& c : cases) {
    auto bad = bytes;
    if (c.bytes == 4)
      poke(bad, c.at, uint32_t(c.value));
    else
      poke(bad, c.at, c.value);
    error.clear();
    EXPECT_FALSE(blasFrom(bad, bad.size(), &error)) << c.what;
    EXPECT_FALSE(error.empty()) << c.what;
  }
  // Tlas: u32 instance count at 32, u32 reference count at 36, instances (72 bytes) from 40, each with its Blas
  // reference at 40 + 72 i + 64.
  std::vector<const Blas*> refs;
  const auto tbytes = serialize(*w.tlas, &refs);
  const std::vector<std::shared_ptr<const Blas>> resolved{nullptr, w.a, w.b, w.a};
  for (auto [at, value] : std::vector<std::pair<size_t, uint32_t>>{
           {32, 5}, {32, 3}, {32, 0x04000000}, {36, 3}, {40 + 72 + 64, 4}, {40 + 72 + 64, 0xFFFFFFFEu}}) {
    auto bad = tbytes;
    poke(bad, at, value);
    error.clear();
    EXPECT_FALSE(tlasFrom(bad, bad.size(), resolved, &error)) << at << " " << value;
    EXPECT_FALSE(error.empty());
  }
}

}  // namespace
}  // namespace vkrt::accel::test
