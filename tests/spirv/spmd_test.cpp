// SPMD compilation of compute shaders (src/spirv/spmd.cpp) against the scalar path, its reference: the same
// shader compiled both ways (spirv::setSpmd) and dispatched on the same inputs writes the same bytes, for
// workgroups of 1, 7, 64 and 100 invocations, 3D ones, and ones whose rows a batch spans or not; shaders with workgroup
// barriers and workgroup memory too (their batches run as fibers). Each test also
// checks that the SPMD compile really took the SPMD path (CompiledShader::spmdLanes), so none passes vacuously.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <string>

#include "compute_harness.hpp"
#include "compute_shared.comp.spv.h"
#include "group_bounds_saxpy.comp.spv.h"
#include "spmd_atomics.comp.spv.h"
#include "spmd_barrier_locals.comp.spv.h"
#include "spmd_barriers.comp.spv.h"
#include "spmd_control.comp.spv.h"
#include "spmd_integer_dot.spv14.spvasm.spv.h"
#include "spmd_switch_break.spvasm.spv.h"

namespace vkrt::testing {
namespace {

spirv::SpecValue spec(uint32_t id, uint32_t v) {
  spirv::SpecValue s{id, std::vector<uint8_t>(4)};
  std::memcpy(s.bytes.data(), &v, 4);
  return s;
}

struct Shape {
  uint32_t size[3];
  uint32_t groups[3];
};

// Runs spmd_control.comp for `shape` with SPMD on or off; returns both output buffers' bytes.
// `lanes`: the shader's spmdLanes; `targetLanes`: the setting's (0 when off).
std::vector<uint32_t> runControl(const Shape& shape, bool spmd, uint32_t* lanes, uint32_t* targetLanes) {
  SpmdSetting setting(spmd);
  *targetLanes = spirv::spmdLanes();
  ComputeHarness h;
  EXPECT_TRUE(
      h.compile(kSpv_spmd_control_comp, {spec(0, shape.size[0]), spec(1, shape.size[1]), spec(2, shape.size[2])}))
      << h.error;
  if (!h.shader) return {};
  *lanes = h.shader->spmdLanes;
  uint32_t total = 1;
  for (int i = 0; i < 3; ++i) total *= shape.size[i] * shape.groups[i];
  uint32_t n = total - total / 5;  // the last invocations return at once
  std::vector<float> in(n);
  for (uint32_t i = 0; i < n; ++i) in[i] = float((i * 2654435761u) % 1000u) / 1000.0f;
  h.setBuffer(1, in);
  h.setBuffer(0, std::vector<uint32_t>(size_t(n) * 8, 0xdeadbeefu));
  h.setBuffer(2, std::vector<uint32_t>(size_t(n) + 2, 0xdeadbeefu));
  struct {
    uint32_t n, maxIter, bias;
    float scale;
  } push = {n, 200, 5, 1.5f};
  std::memcpy(h.push, &push, sizeof push);
  EXPECT_TRUE(h.run(shape.groups[0], shape.groups[1], shape.groups[2]));
  std::vector<uint32_t> out = h.get<uint32_t>(0);
  std::vector<uint32_t> out2 = h.get<uint32_t>(2);
  out.insert(out.end(), out2.begin(), out2.end());
  return out;
}

void compareControl(const Shape& shape) {
  uint32_t scalarLanes = 99, spmdLanes = 0, target = 0, off = 99;
  std::vector<uint32_t> scalar = runControl(shape, false, &scalarLanes, &off);
  std::vector<uint32_t> spmd = runControl(shape, true, &spmdLanes, &target);
  EXPECT_EQ(off, 0u);
  EXPECT_EQ(scalarLanes, 0u) << "VKRT_SPMD=0's path runs invocations one by one";
  EXPECT_EQ(spmdLanes, target) << "the shader did not take the SPMD path";
  EXPECT_GE(spmdLanes, 4u);
  ASSERT_EQ(scalar.size(), spmd.size());
  ASSERT_FALSE(scalar.empty());
  size_t written = 0;
  for (size_t i = 0; i < scalar.size(); ++i) {
    ASSERT_EQ(spmd[i], scalar[i]) << "word " << i << " (record " << i / 8 << ", field " << i % 8 << ")";
    written += scalar[i] != 0xdeadbeefu;
  }
  EXPECT_GT(written, scalar.size() / 2) << "the shader wrote its outputs";
}

TEST(Spmd, LanesFollowTheTarget) {
  SpmdSetting on(true);
  unsigned lanes = spirv::spmdLanes();
  EXPECT_TRUE(lanes == 8 || lanes == 16) << lanes;
  // The baselines the instruction-set matrix runs: AVX2 takes 16 lanes in two registers, SSE4.2 8.
  const char* cpu = std::getenv("VKRT_JIT_CPU");
  if (cpu && std::string(cpu) == "x86-64-v3") {
    EXPECT_EQ(lanes, 16u);
  }
  if (cpu && std::string(cpu) == "x86-64-v2") {
    EXPECT_EQ(lanes, 8u);
  }
  SpmdSetting off(false);
  EXPECT_EQ(spirv::spmdLanes(), 0u);
}

TEST(Spmd, MatchesScalarWorkgroupOfOne) { compareControl({{1, 1, 1}, {37, 1, 1}}); }
TEST(Spmd, MatchesScalarWorkgroupOfSeven) { compareControl({{7, 1, 1}, {9, 2, 1}}); }
TEST(Spmd, MatchesScalarWorkgroupOf64) { compareControl({{64, 1, 1}, {5, 1, 1}}); }
TEST(Spmd, MatchesScalarWorkgroupOf100) { compareControl({{100, 1, 1}, {3, 1, 2}}); }
TEST(Spmd, MatchesScalarWorkgroup3D) { compareControl({{4, 3, 5}, {2, 2, 2}}); }
TEST(Spmd, MatchesScalarRowsOfSixteen) { compareControl({{16, 16, 1}, {2, 2, 1}}); }
TEST(Spmd, MatchesScalarRowsOfThirtyTwo) { compareControl({{32, 2, 2}, {2, 1, 2}}); }

TEST(Spmd, SurvivesThePipelineCache) {
  SpmdSetting on(true);
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_group_bounds_saxpy_comp)) << h.error;
  ASSERT_EQ(h.shader->spmdLanes, spirv::spmdLanes());
  std::string error;
  auto cached = spirv::loadCached(h.shader->cacheBlob, nullptr, &error);
  ASSERT_NE(cached, nullptr) << error;
  EXPECT_EQ(cached->spmdLanes, h.shader->spmdLanes);
  EXPECT_NE(cached->groupEntry, nullptr);
}

TEST(Spmd, CacheKeyHoldsTheSetting) {
  spirv::CompileRequest r;
  r.words = kSpv_group_bounds_saxpy_comp;
  r.wordCount = sizeof kSpv_group_bounds_saxpy_comp / 4;
  std::string on, off;
  {
    SpmdSetting s(true);
    on = spirv::cacheKey(r);
  }
  {
    SpmdSetting s(false);
    off = spirv::cacheKey(r);
  }
  EXPECT_NE(on, off);
}

// Workgroup barriers and workgroup memory (tests/shaders/spmd_barriers.comp): the SPMD path runs a workgroup's
// batches as fibers that switch at each barrier. Both paths against what the invocations compute (here, from the
// inputs), for workgroups of one batch, of a batch and a tail, of several, and of every lane count up to 256; with
// the branch of barriers taken and not. Workgroup memory is bounds-checked as buffers are: a store past an array is
// dropped, a load past it reads 0.
void expectBarriers(uint32_t sx, uint32_t sy, uint32_t rounds, uint32_t flag) {
  const uint32_t n = sx * sy, groups = 3;
  std::vector<uint32_t> in(size_t(n) * groups);
  for (size_t i = 0; i < in.size(); ++i) in[i] = uint32_t(i * 2654435761u) >> 3;
  // The workgroups as the shader computes them, invocation by invocation.
  std::vector<uint32_t> want(size_t(n) * groups * 5);
  for (uint32_t wg = 0; wg < groups; ++wg) {
    std::vector<uint32_t> a(in.begin() + size_t(wg) * n, in.begin() + size_t(wg + 1) * n), b(n);
    uint32_t maxv = 0;
    for (uint32_t x : a) maxv = std::max(maxv, x ^ 0x5a5a5a5au);
    for (uint32_t r = 0; r < rounds; ++r) {
      std::vector<uint32_t> next(n);
      for (uint32_t l = 0; l < n; ++l) next[l] = a[(l + n - 1) % n] * 3u + a[(l + 1) % n] + r;
      a = next;
    }
    if (flag) {
      for (uint32_t l = 0; l < n; ++l) b[l] = a[n - 1 - l];
      for (uint32_t l = 0; l < n; ++l) a[l] = b[l] + 1u;
    }
    uint32_t sum = 0;
    for (uint32_t x : a) sum += x;
    for (uint32_t l = 0; l < n; ++l) {
      const size_t g = size_t(wg) * n + l;
      want[5 * g] = a[l], want[5 * g + 1] = sum, want[5 * g + 2] = n, want[5 * g + 3] = maxv;
      want[5 * g + 4] = (l & 1) == 0 ? a[(l * 7) % n] : 0u;  // odd lanes read past the array
    }
  }
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_barriers_comp, {spec(0, sx), spec(1, sy)})) << h.error;
    ASSERT_TRUE(h.shader->usesBarrier);
    EXPECT_EQ(h.shader->spmdLanes, spmd ? spirv::spmdLanes() : 0u) << "the path the shader took";
    EXPECT_EQ(h.shader->groupEntry != nullptr, spmd);
    h.setBuffer(0, in);
    h.setBuffer(1, std::vector<uint32_t>(want.size(), 0xdeadbeefu));
    const uint32_t push[2] = {rounds, flag};
    std::memcpy(h.push, push, sizeof push);
    ASSERT_TRUE(h.run(groups));
    const std::vector<uint32_t> out = h.get<uint32_t>(1);
    ASSERT_EQ(out.size(), want.size());
    for (size_t i = 0; i < want.size(); ++i) ASSERT_EQ(out[i], want[i]) << "invocation " << i / 5 << " word " << i % 5;
  }
}

TEST(Spmd, BarriersWorkgroupOfOne) { expectBarriers(1, 1, 3, 1); }
TEST(Spmd, BarriersWorkgroupOfTwenty) { expectBarriers(20, 1, 3, 1); }
TEST(Spmd, BarriersWorkgroupOf64) { expectBarriers(64, 1, 5, 0); }
TEST(Spmd, BarriersWorkgroupOf100) { expectBarriers(100, 1, 2, 1); }
TEST(Spmd, BarriersWorkgroup16By16) { expectBarriers(16, 16, 4, 1); }
TEST(Spmd, BarriersWorkgroup7By3NoRounds) { expectBarriers(7, 3, 0, 0); }

// A batch of a shader with barriers runs on a fiber's stack: Function variables of N lanes that would not fit
// (spmd.cpp, kMaxBatchFiberLaneBytes) keep the shader on the scalar path, whose fibers hold one invocation's; both
// compute what the invocations compute.
TEST(Spmd, BarrierShadersWithLargeLocalsStayScalar) {
  SpmdSetting on(true);
  for (uint32_t len : {16u, 4096u}) {
    SCOPED_TRACE(len);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_barrier_locals_comp, {spec(0, len)})) << h.error;
    EXPECT_EQ(h.shader->spmdLanes, len == 16 ? spirv::spmdLanes() : 0u) << "16 words SPMD, 4,096 scalar";
    h.setBuffer(0, std::vector<uint32_t>(64, 0xdeadbeefu));
    ASSERT_TRUE(h.run(2));
    const std::vector<uint32_t> out = h.get<uint32_t>(0);
    for (uint32_t wg = 0; wg < 2; ++wg)
      for (uint32_t l = 0; l < 32; ++l) {
        const uint32_t other = 31 - l;
        EXPECT_EQ(out[wg * 32 + l], other * ((other * 7) % len) + wg + l * (len - 1) + wg) << wg << " " << l;
      }
  }
}

// compute_shared.comp (a reversal, a tree reduction and a workgroup atomic) on both paths: the same bytes.
TEST(Spmd, SharedMemoryShaderWritesWhatTheScalarPathWrites) {
  std::vector<uint32_t> results[2];
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_compute_shared_comp)) << h.error;
    EXPECT_EQ(h.shader->spmdLanes, spmd ? spirv::spmdLanes() : 0u);
    std::vector<uint32_t> data(64 * 4);
    for (uint32_t i = 0; i < data.size(); ++i) data[i] = i * 7u + 3u;
    h.setBuffer(0, data);
    h.setBuffer(1, std::vector<uint32_t>(8, 0xdeadbeefu));
    ASSERT_TRUE(h.run(4));
    results[spmd] = h.get<uint32_t>(0);
    const std::vector<uint32_t> sums = h.get<uint32_t>(1);
    results[spmd].insert(results[spmd].end(), sums.begin(), sums.end());
    for (uint32_t wg = 0; wg < 4; ++wg) {
      uint32_t sum = 0;
      for (uint32_t l = 0; l < 64; ++l) sum += data[wg * 64 + l];
      EXPECT_EQ(sums[2 * wg], sum) << wg;
      EXPECT_EQ(sums[2 * wg + 1], 64u) << wg;
    }
  }
  EXPECT_EQ(results[1], results[0]);
}

// Atomics lane by lane (spmd.cpp, atomicLanes): one workgroup; each atomic instruction runs for the invocations in
// their order on both paths. The SPMD path is taken and writes what the scalar path writes, and both what is computed
// here.
TEST(Spmd, AtomicsRunLaneByLaneInOrder) {
  std::vector<uint32_t> results[2];
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_atomics_comp)) << h.error;
    if (spmd) ASSERT_NE(h.shader->spmdLanes, 0u) << "the shader did not take the SPMD path";
    h.setBuffer(0, std::vector<uint32_t>{0, ~0u, 0, 0, ~0u, 0, 0x7fffffff, uint32_t(INT32_MIN), 0, 1000, 7, 0});
    h.setBuffer(1, std::vector<uint32_t>(16, 0));
    h.setBuffer(2, std::vector<uint32_t>(64 * 4, 0xdeadbeefu));
    h.setBuffer(3, std::vector<uint32_t>(64, 0xdeadbeefu));
    ASSERT_TRUE(h.run(1));
    for (uint32_t b = 0; b < 4; ++b) {
      std::vector<uint32_t> words = h.get<uint32_t>(b);
      results[spmd].insert(results[spmd].end(), words.begin(), words.end());
    }
  }
  EXPECT_EQ(results[1], results[0]);
  // What the invocations in order give.
  std::vector<uint32_t> c = {0, ~0u, 0, 0, ~0u, 0, 0x7fffffff, uint32_t(INT32_MIN), 0, 1000, 7, 0}, bins(16, 0);
  std::vector<uint32_t> o(64 * 4, 0xdeadbeefu), items(64, 0xdeadbeefu);
  for (uint32_t i = 0; i < 64; ++i) {
    const uint32_t v = (i * 2654435761u) >> 7;
    ++bins[v % 16];
    const uint32_t s = c[0]++;
    items[s] = v;
    c[1] = std::min(c[1], v), c[2] = std::max(c[2], v), c[3] |= 1u << (i % 32), c[4] &= ~(1u << (i % 29)), c[5] ^= v;
    c[6] = uint32_t(std::min(int32_t(c[6]), int32_t(v % 1000003u) - 500000));
    c[7] = uint32_t(std::max(int32_t(c[7]), int32_t(v % 977u) - 500));
    const uint32_t old = c[8];
    if (c[8] == i) c[8] = i + 1;
    const uint32_t e = c[9];
    c[9] = i;
    if (i % 4 != 3) {
      o[i * 4] = s;
      o[i * 4 + 3] += 5;
    } else {
      c[10] = i;
    }
    o[i * 4 + 1] = old, o[i * 4 + 2] = e;
  }
  std::vector<uint32_t> want = c;
  want.insert(want.end(), bins.begin(), bins.end());
  want.insert(want.end(), o.begin(), o.end());
  want.insert(want.end(), items.begin(), items.end());
  EXPECT_EQ(results[1], want);
}

// A conditional branch without a merge of its own that breaks out of a switch (tests/shaders/spmd_switch_break.spvasm):
// the lanes meet at the switch's merge by different edges, so its phi of two constants varies.
TEST(Spmd, ABreakOutOfASwitchMeetsTheOtherLanesAtItsMerge) {
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_switch_break_spvasm)) << h.error;
    if (spmd) ASSERT_NE(h.shader->spmdLanes, 0u) << "the shader did not take the SPMD path";
    h.setBuffer(0, std::vector<uint32_t>(64, 0));
    ASSERT_TRUE(h.run(4));
    const std::vector<uint32_t> out = h.get<uint32_t>(0);
    for (uint32_t i = 0; i < 64; ++i) EXPECT_EQ(out[i], (i & 1) ? 11u : 12u) << i;
  }
}

// Integer dot products (SPV_KHR_integer_dot_product) on the SPMD path: the scalar code's, lane by lane
// (tests/shaders/spmd_integer_dot.spv14.spvasm: vector and packed operands, signed, unsigned and mixed, a saturating
// accumulation), against values computed here.
TEST(Spmd, IntegerDotProductsLaneByLane) {
  for (bool spmd : {false, true}) {
    SCOPED_TRACE(spmd ? "SPMD" : "scalar");
    SpmdSetting setting(spmd);
    ComputeHarness h;
    ASSERT_TRUE(h.compile(kSpv_spmd_integer_dot_spv14_spvasm)) << h.error;
    if (spmd) ASSERT_NE(h.shader->spmdLanes, 0u) << "the shader did not take the SPMD path";
    h.setBuffer(0, std::vector<uint32_t>(64 * 4, 0xdeadbeefu));
    ASSERT_TRUE(h.run(4));
    const std::vector<uint32_t> out = h.get<uint32_t>(0);
    for (int32_t i = 0; i < 64; ++i) {
      SCOPED_TRACE(i);
      const int32_t a[4] = {i - 8, 3, -i, 7}, b[4] = {2, i, 5, -1};
      int64_t d0 = 0, d3 = 0;
      for (int k = 0; k < 4; ++k) d0 += int64_t(a[k]) * b[k], d3 += int64_t(a[k]) * 2;
      const uint32_t pa = uint32_t(i) * 0x01020304u, pb = 0x80ff7f01u;
      int64_t u = 0, su = 0;
      for (int k = 0; k < 4; ++k) {
        const uint8_t x = uint8_t(pa >> (8 * k)), y = uint8_t(pb >> (8 * k));
        u += int64_t(x) * y;
        su += int64_t(int8_t(x)) * y;
      }
      const int64_t acc = int64_t(int32_t(0x7fffff00u + uint32_t(i))) + su;
      const int64_t sat = std::clamp<int64_t>(acc, INT32_MIN, INT32_MAX);
      EXPECT_EQ(out[i * 4], uint32_t(int32_t(d0)));
      EXPECT_EQ(out[i * 4 + 1], uint32_t(u));
      EXPECT_EQ(out[i * 4 + 2], uint32_t(int32_t(sat)));
      EXPECT_EQ(out[i * 4 + 3], uint32_t(int32_t(d3)));
    }
  }
}

}  // namespace
}  // namespace vkrt::testing
