// The per-workgroup entry point (vkrt_group): generated for shaders without barriers (instead of the
// per-invocation vkrt_main), it must give every invocation its own built-ins and fresh private variables,
// survive the pipeline cache's round trip, and keep out-of-bounds accesses contained in its loop, vectorized
// (masked loads and stores) or not.
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <map>

#include "compute_harness.hpp"
#include "compute_shared.comp.spv.h"
#include "group_bounds_gather.comp.spv.h"
#include "group_bounds_saxpy.comp.spv.h"
#include "group_builtins.comp.spv.h"

namespace vkrt::testing {
namespace {

constexpr uint32_t kSize[3] = {4, 3, 2};

// Dispatches 3x2x2 workgroups with a base of (1, 0, 2) (the push constants describe the whole grid, base
// included) and checks every invocation's record.
void runAndCheck(ComputeHarness& h) {
  const uint32_t count[3] = {3, 2, 2}, base[3] = {1, 0, 2};
  const uint32_t groups[3] = {count[0] + base[0], count[1] + base[1], count[2] + base[2]};
  const uint32_t width = groups[0] * kSize[0], height = groups[1] * kSize[1], depth = groups[2] * kSize[2];
  uint32_t push[2] = {groups[0], groups[1]};
  std::memcpy(h.push, push, sizeof push);
  const uint32_t sentinel = 0xdeadbeefu;
  h.setBuffer(0, std::vector<uint32_t>(size_t(width) * height * depth * 12, sentinel));
  ASSERT_TRUE(h.run(count[0], count[1], count[2], base[0], base[1], base[2]));
  std::vector<uint32_t> out = h.get<uint32_t>(0);
  size_t written = 0;
  for (uint32_t z = 0; z < depth; ++z)
    for (uint32_t y = 0; y < height; ++y)
      for (uint32_t x = 0; x < width; ++x) {
        const uint32_t g[3] = {x, y, z};
        const uint32_t* r = &out[((size_t(z) * height + y) * width + x) * 12];
        bool inDispatch = true;
        for (int i = 0; i < 3; ++i) inDispatch &= g[i] / kSize[i] >= base[i];
        if (!inDispatch) {
          for (int i = 0; i < 12; ++i)
            ASSERT_EQ(r[i], sentinel) << "outside the dispatch at " << x << "," << y << "," << z;
          continue;
        }
        ++written;
        uint32_t l[3], w[3];
        for (int i = 0; i < 3; ++i) {
          l[i] = g[i] % kSize[i];
          w[i] = g[i] / kSize[i];
        }
        uint32_t index = (l[2] * kSize[1] + l[1]) * kSize[0] + l[0];
        const uint32_t expect[12] = {x, y, z, index, l[0], l[1], l[2], 7 + index, w[0], w[1], w[2], count[0]};
        for (int i = 0; i < 12; ++i)
          ASSERT_EQ(r[i], expect[i]) << "field " << i << " of invocation " << x << "," << y << "," << z;
      }
  EXPECT_EQ(written, size_t(count[0]) * count[1] * count[2] * 24);
}

TEST(SpirvGroupEntry, BuiltInsAndPrivateVariablesPerInvocation) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_builtins_comp)) << h.error;
  EXPECT_FALSE(h.shader->usesBarrier);
  ASSERT_NE(h.shader->groupEntry, nullptr) << "a shader without barriers gets the per-workgroup entry";
  EXPECT_EQ(h.shader->entry, nullptr) << "the per-invocation function is only kept for shaders with barriers";
  runAndCheck(h);
}

// A shader with barriers keeps vkrt_main (one fiber per invocation) where it is not compiled SPMD; compiled SPMD, its
// vkrt_group runs one batch of the workgroup (spmd_test.cpp runs both).
TEST(SpirvGroupEntry, ShadersWithBarriersHaveNoneOffTheSpmdPath) {
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_compute_shared_comp)) << h.error;
    EXPECT_TRUE(h.shader->usesBarrier);
    EXPECT_EQ(h.shader->groupEntry != nullptr, spmd);
    EXPECT_EQ(h.shader->entry != nullptr, !spmd);
    EXPECT_EQ(h.shader->spmdLanes, spirv::spmdLanes());
    std::string error;
    auto cached = spirv::loadCached(h.shader->cacheBlob, nullptr, &error);
    ASSERT_NE(cached, nullptr) << error;
    EXPECT_EQ(cached->groupEntry != nullptr, spmd);
    EXPECT_EQ(cached->entry != nullptr, !spmd);
    EXPECT_EQ(cached->spmdLanes, h.shader->spmdLanes);
    EXPECT_TRUE(cached->usesBarrier);
  }
}

TEST(SpirvGroupEntry, SurvivesThePipelineCache) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_builtins_comp)) << h.error;
  std::string error;
  auto cached = spirv::loadCached(h.shader->cacheBlob, nullptr, &error);
  ASSERT_NE(cached, nullptr) << error;
  ASSERT_NE(cached->groupEntry, nullptr);
  EXPECT_EQ(cached->entry, nullptr);
  EXPECT_EQ(cached->localSize[2], 2u);
  h.shader = cached;
  runAndCheck(h);
}

// ---- out-of-bounds accesses in the per-workgroup loop
//
// The buffers of these tests end right where an inaccessible page begins, and the bytes before them are
// canaries: a read or a write past the end faults, a write before the start changes the canaries.

class FencedBuffer {
 public:
  explicit FencedBuffer(size_t bytes) : bytes_(bytes) {
    size_t page = size_t(sysconf(_SC_PAGESIZE));
    size_t body = (bytes + page - 1) / page * page + page;  // at least a page of canaries before the data
    mapBytes_ = body + page;
    void* m = mmap(nullptr, mapBytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) return;
    map_ = static_cast<uint8_t*>(m);
    mprotect(map_ + body, page, PROT_NONE);
    data_ = map_ + body - bytes;
    std::memset(map_, kCanary, size_t(data_ - map_));
  }
  ~FencedBuffer() {
    if (map_) munmap(map_, mapBytes_);
  }
  FencedBuffer(const FencedBuffer&) = delete;
  FencedBuffer& operator=(const FencedBuffer&) = delete;

  template <class T>
  T* as() {
    return reinterpret_cast<T*>(data_);
  }
  size_t bytes() const { return bytes_; }
  bool canariesIntact() const {
    for (const uint8_t* p = map_; p < data_; ++p)
      if (*p != kCanary) return false;
    return true;
  }

 private:
  static constexpr uint8_t kCanary = 0xa5;
  uint8_t* map_ = nullptr;
  size_t mapBytes_ = 0;
  uint8_t* data_ = nullptr;
  size_t bytes_ = 0;
};

// Runs `shader` with set 0's bindings taken from `buffers` (by binding number; a missing one is unbound).
bool dispatchFenced(const spirv::CompiledShader& shader, const std::map<uint32_t, FencedBuffer*>& buffers,
                    const void* push, size_t pushBytes, uint32_t x, uint32_t y) {
  std::vector<abi::DescriptorRecord> records(shader.resources.size());
  std::vector<abi::ResourceSlot> slots(shader.resources.size());
  for (size_t i = 0; i < shader.resources.size(); ++i) {
    auto it = buffers.find(shader.resources[i].binding);
    if (it == buffers.end()) {
      slots[i] = {nullptr, 0};  // nothing bound
      continue;
    }
    records[i] = abi::DescriptorRecord{};
    records[i].address = reinterpret_cast<uint64_t>(it->second->as<uint8_t>());
    records[i].range = it->second->bytes();
    slots[i] = {&records[i], 1};
  }
  alignas(16) uint8_t pushData[abi::kPushConstantBytes] = {};
  std::memcpy(pushData, push, pushBytes);
  exec::ComputeDispatch d;
  d.kernel = computeKernel(shader);
  d.resources = slots.data();
  d.pushConstants = pushData;
  d.count[0] = x;
  d.count[1] = y;
  return exec::runCompute(d);
}

float saxpyX(uint32_t i) { return float(i % 7) * 0.25f; }
float saxpyY(uint32_t i) { return float(i % 13) - 6.0f; }

TEST(SpirvGroupEntry, OutOfBoundsReadsZeroAndDropsWritesInTheVectorizedLoop) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_bounds_saxpy_comp)) << h.error;
  ASSERT_NE(h.shader->groupEntry, nullptr);
  // 256 invocations over an x of 150 floats and a y of 201: neither ends at a workgroup or vector boundary.
  const uint32_t nx = 150, ny = 201;
  FencedBuffer x(nx * 4), y(ny * 4);
  for (uint32_t i = 0; i < nx; ++i) x.as<float>()[i] = saxpyX(i);
  for (uint32_t i = 0; i < ny; ++i) y.as<float>()[i] = saxpyY(i);
  const float a = 1.5f;  // exact products and sums: fused or not, the same floats
  ASSERT_TRUE(dispatchFenced(*h.shader, {{0, &x}, {1, &y}}, &a, 4, 4, 1));
  for (uint32_t i = 0; i < ny; ++i) EXPECT_EQ(y.as<float>()[i], a * (i < nx ? saxpyX(i) : 0.0f) + saxpyY(i)) << i;
  for (uint32_t i = 0; i < nx; ++i) EXPECT_EQ(x.as<float>()[i], saxpyX(i)) << i;
  EXPECT_TRUE(x.canariesIntact());
  EXPECT_TRUE(y.canariesIntact());
}

TEST(SpirvGroupEntry, UnboundBuffersReadZeroAndDropWrites) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_bounds_saxpy_comp)) << h.error;
  const uint32_t n = 128;
  FencedBuffer x(n * 4), y(n * 4);
  for (uint32_t i = 0; i < n; ++i) {
    x.as<float>()[i] = saxpyX(i);
    y.as<float>()[i] = saxpyY(i);
  }
  const float a = 1.5f;
  // x unbound: y = a * 0 + y.
  ASSERT_TRUE(dispatchFenced(*h.shader, {{1, &y}}, &a, 4, 2, 1));
  for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(y.as<float>()[i], saxpyY(i)) << i;
  // y unbound: nothing is written anywhere.
  ASSERT_TRUE(dispatchFenced(*h.shader, {{0, &x}}, &a, 4, 2, 1));
  for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(x.as<float>()[i], saxpyX(i)) << i;
  EXPECT_TRUE(x.canariesIntact());
  EXPECT_TRUE(y.canariesIntact());
}

TEST(SpirvGroupEntry, WildIndicesAndStraddlingVectorsAreContained) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_bounds_gather_comp)) << h.error;
  ASSERT_NE(h.shader->groupEntry, nullptr);
  const uint32_t invocations = 256, nSrc = 100, nGathered = 250, nVectors = 200;
  FencedBuffer src(nSrc * 4), index(invocations * 4), gathered(nGathered * 4), vectors(nVectors * 16 + 8);
  for (uint32_t k = 0; k < nSrc; ++k) src.as<float>()[k] = float(k) + 0.5f;
  const uint32_t wild[5] = {nSrc - 1, nSrc, 0xffffffffu, 0x40000000u, 0};
  for (uint32_t i = 0; i < invocations; ++i) index.as<uint32_t>()[i] = i % 5 == 4 ? i % nSrc : wild[i % 5];
  for (uint32_t i = 0; i < nGathered; ++i) gathered.as<float>()[i] = -1.0f;
  float* v = vectors.as<float>();
  for (uint32_t k = 0; k < nVectors * 4 + 2; ++k) v[k] = float(k % 9);
  const int32_t shift = 20;  // src[i - 20]: negative indices for the first 20 invocations
  ASSERT_TRUE(dispatchFenced(*h.shader, {{0, &src}, {1, &index}, {2, &gathered}, {3, &vectors}}, &shift, 4, 2, 2));
  auto srcAt = [&](int64_t k) { return k >= 0 && k < nSrc ? float(k) + 0.5f : 0.0f; };
  for (uint32_t i = 0; i < nGathered; ++i)
    EXPECT_EQ(gathered.as<float>()[i], srcAt(index.as<uint32_t>()[i]) + srcAt(int64_t(i) - shift)) << i;
  const float add[4] = {1, 2, 3, 4};
  for (uint32_t k = 0; k < nVectors * 4; ++k) EXPECT_EQ(v[k], float(k % 9) * 2.0f + add[k % 4]) << k;
  // The vec4 that straddles the end is neither read (it would count as zeros) nor written, not even in part.
  EXPECT_EQ(v[nVectors * 4], float((nVectors * 4) % 9));
  EXPECT_EQ(v[nVectors * 4 + 1], float((nVectors * 4 + 1) % 9));
  for (FencedBuffer* b : {&src, &index, &gathered, &vectors}) EXPECT_TRUE(b->canariesIntact());
}

}  // namespace
}  // namespace vkrt::testing
