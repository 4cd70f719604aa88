// Combined counter adds (abi::PendingAdds, src/abi/abi.hpp): in ray tracing stages an atomic add or subtract whose
// result is unused, Relaxed, on a buffer reached through a descriptor, goes to the worker's pending sum instead of
// memory. combined_adds.rgen's modes pair such adds with what must write the sum first (a load, store or atomic of
// the word, any other atomic, a barrier, an add to another word) and with what must not be combined at all (a
// used result, release semantics); each test checks memory right after the shader ran, before the executor's own
// flush, and the table. Without a table (null pendingAdds) every add is atomic where the shader has it, and the
// memory after the launch is the same.
#include <gtest/gtest.h>

#include <cstring>
#include <iterator>

#include "combined_adds.rahit.spv.h"
#include "combined_adds.rgen.spv.h"
#include "combined_adds_sub.spv14.spvasm.spv.h"
#include "compute_memory_model.comp.spv.h"
#include "spirv/ray_runtime.hpp"
#include "trace_raygen.rgen.spv.h"

namespace vkrt::testing {
namespace {

constexpr uint64_t kAccel = 0xa5a5a000;

struct Words {
  uint32_t counter, other, seen[6];
  uint64_t wide;
};
static_assert(sizeof(Words) == 40);

int gFlushes = 0;
void countingFlush(abi::PendingAdds* adds) {
  ++gFlushes;
  abi::flushPendingAdds(adds);
}

// Compiled as a pipeline with such adds compiles its stages (CompileRequest::combineAdds), or without it.
template <size_t N>
std::shared_ptr<spirv::CompiledShader> compileStage(const uint32_t (&words)[N], spv::ExecutionModel model,
                                                    bool combineAdds = true) {
  spirv::CompileRequest r;
  r.words = words;
  r.wordCount = N;
  r.model = model;
  r.combineAdds = combineAdds;
  std::string error;
  auto s = spirv::compile(r, &error);
  EXPECT_TRUE(s) << error;
  return s;
}

struct Launch {
  Words words{};                                               // right after the launch
  abi::PendingAdds table{~uint64_t(0), 0, 0, &countingFlush};  // right after the launch
  int flushes = 0;                                             // by the shaders
  uint64_t address(const void* field) const { return reinterpret_cast<uint64_t>(field); }
};

// Runs `raygen` (push constant: mode) for `width` launch indices over a scene of one triangle under (0.25, 0.25)
// at z = 1 whose hit group has combined_adds.rahit, with a table (`combined`) or without. `run.words` is the buffer.
void launch(const std::shared_ptr<spirv::CompiledShader>& raygen, uint32_t mode, bool combined, Launch& run,
            uint32_t width = 1) {
  static const std::shared_ptr<spirv::CompiledShader> ahit =
      compileStage(kSpv_combined_adds_rahit, spv::ExecutionModelAnyHitKHR);
  ASSERT_TRUE(raygen && ahit);
  RayScene scene;
  RayScene::Instance instance;
  RayScene::Geometry triangle;
  triangle.triangles = {{{{-1, -1, 1}, {2, -1, 1}, {-1, 2, 1}}}};
  instance.geometries = {triangle};
  scene.instances = {instance};
  RaySbt sbt;
  sbt.hitGroups = {{nullptr, nullptr, ahit, nullptr, {}}};
  RayTestRuntime rt(scene, sbt, kAccel);
  rt.pendingAdds = combined ? &run.table : nullptr;
  rt.pushConstants = reinterpret_cast<const uint8_t*>(&mode);
  rt.bindings[0] = abi::DescriptorRecord{kAccel, 0, nullptr, nullptr};
  rt.bindings[1] = abi::DescriptorRecord{reinterpret_cast<uint64_t>(&run.words), sizeof run.words, nullptr, nullptr};
  gFlushes = 0;
  rt.launch(raygen, {}, width, 1);
  run.flushes = gFlushes;
  EXPECT_TRUE(rt.errors.empty()) << rt.errors.front();
}

const std::shared_ptr<spirv::CompiledShader>& raygen() {
  static const std::shared_ptr<spirv::CompiledShader> s =
      compileStage(kSpv_combined_adds_rgen, spv::ExecutionModelRayGenerationKHR);
  return s;
}

bool empty(const abi::PendingAdds& t) { return t.end == 0 && t.begin == ~uint64_t(0) && t.sum == 0; }

TEST(SpirvCombinedAdds, AddsWithUnusedResultsArePendingUntilFlushed) {
  Launch r;
  launch(raygen(), 0, true, r);
  EXPECT_EQ(r.words.counter, 0u) << "nothing written while the sum is pending";
  EXPECT_EQ(r.words.other, 11u);
  EXPECT_EQ(r.flushes, 0) << "a store to another word writes nothing";
  EXPECT_EQ(r.table.begin, r.address(&r.words.counter));
  EXPECT_EQ(r.table.end, r.address(&r.words.counter) + 4);
  EXPECT_EQ(uint32_t(r.table.sum), 2u) << "1 + 2 + 0xffffffff modulo 2^32";
  abi::flushPendingAdds(&r.table);
  EXPECT_EQ(r.words.counter, 2u);
  EXPECT_TRUE(empty(r.table));
}

TEST(SpirvCombinedAdds, ALoadOrAStoreOfThePendingWordWritesItFirst) {
  Launch load;
  launch(raygen(), 1, true, load);
  EXPECT_EQ(load.words.seen[0], 1u) << "the invocation's own add, seen by its load";
  EXPECT_EQ(load.words.counter, 1u);
  EXPECT_EQ(load.flushes, 1);
  EXPECT_TRUE(empty(load.table));
  Launch store;
  launch(raygen(), 2, true, store);
  EXPECT_EQ(store.words.counter, 7u) << "the store comes after the add";
  EXPECT_EQ(store.flushes, 1);
  EXPECT_TRUE(empty(store.table));
}

TEST(SpirvCombinedAdds, OtherAtomicsBarriersAndOtherWordsWriteTheSumFirst) {
  Launch exchange;
  launch(raygen(), 3, true, exchange);
  EXPECT_EQ(exchange.words.counter, 2u) << "an atomic on another word";
  EXPECT_EQ(exchange.words.seen[1], 0u);
  EXPECT_EQ(exchange.words.other, 9u);
  EXPECT_TRUE(empty(exchange.table));
  Launch barrier;
  launch(raygen(), 6, true, barrier);
  EXPECT_EQ(barrier.words.counter, 1u) << "memoryBarrierBuffer";
  EXPECT_TRUE(empty(barrier.table));
  Launch wide;
  launch(raygen(), 4, true, wide);
  EXPECT_EQ(wide.words.counter, 1u) << "an add to another word writes the pending one";
  EXPECT_EQ(wide.words.wide, 0u);
  EXPECT_EQ(wide.table.begin, wide.address(&wide.words.wide));
  EXPECT_EQ(wide.table.end, wide.address(&wide.words.wide) + 8);
  EXPECT_EQ(wide.table.sum, 3u);
  abi::flushPendingAdds(&wide.table);
  EXPECT_EQ(wide.words.wide, 3u);
}

TEST(SpirvCombinedAdds, UsedResultsAndReleaseAddsAreNotCombined) {
  Launch used;
  launch(raygen(), 5, true, used);
  EXPECT_EQ(used.words.seen[2], 0u);
  EXPECT_EQ(used.words.seen[3], 1u);
  EXPECT_EQ(used.words.counter, 2u);
  EXPECT_EQ(used.flushes, 0);
  EXPECT_TRUE(empty(used.table));
  Launch release;
  launch(raygen(), 7, true, release);
  EXPECT_EQ(release.words.counter, 1u) << "atomicAdd with gl_SemanticsRelease";
  EXPECT_TRUE(empty(release.table));
}

TEST(SpirvCombinedAdds, AnAnyHitShadersAddIsSeenByTheRaygenAfterItsTrace) {
  Launch r;
  launch(raygen(), 8, true, r);
  EXPECT_EQ(r.words.seen[4], 1u);
  EXPECT_EQ(r.words.counter, 1u);
  EXPECT_EQ(r.flushes, 1);
}

TEST(SpirvCombinedAdds, AnAddToAnotherWordWritesThePreviousOne) {
  Launch r;
  launch(raygen(), 9, true, r, 6);
  for (uint32_t i = 0; i < 5; ++i) EXPECT_EQ(r.words.seen[i], i + 1) << "launch index " << i;
  EXPECT_EQ(r.words.seen[5], 0u) << "the last index's add is pending";
  EXPECT_EQ(r.flushes, 5);
  EXPECT_EQ(r.table.begin, r.address(&r.words.seen[5]));
  EXPECT_EQ(r.table.sum, 6u);
  abi::flushPendingAdds(&r.table);
  EXPECT_EQ(r.words.seen[5], 6u);
}

TEST(SpirvCombinedAdds, SubtractionsArePendingAsNegativeSums) {
  const auto sub = compileStage(kSpv_combined_adds_sub_spv14_spvasm, spv::ExecutionModelRayGenerationKHR);
  Launch r;
  r.words.counter = 10;
  launch(sub, 0, true, r);
  EXPECT_EQ(r.words.counter, 10u);
  EXPECT_EQ(r.words.other, 1u);
  EXPECT_EQ(uint32_t(r.table.sum), uint32_t(-6)) << "OpAtomicISub 5, OpAtomicIDecrement";
  abi::flushPendingAdds(&r.table);
  EXPECT_EQ(r.words.counter, 4u);
  Launch plain;
  plain.words.counter = 10;
  launch(sub, 0, false, plain);
  EXPECT_EQ(plain.words.counter, 4u) << "without a table";
}

TEST(SpirvCombinedAdds, WithoutTheRequestNothingIsCombinedOrChecked) {
  const auto plain = compileStage(kSpv_combined_adds_rgen, spv::ExecutionModelRayGenerationKHR, false);
  ASSERT_TRUE(plain && raygen());
  EXPECT_FALSE(plain->ray.checksPendingAdds);
  EXPECT_TRUE(raygen()->ray.checksPendingAdds);
  Launch r;
  launch(plain, 0, true, r);
  EXPECT_EQ(r.words.counter, 2u) << "every add atomic, though the invocation has a table";
  EXPECT_TRUE(empty(r.table));
  // A compute shader never combines, whatever the request (its relaxed add with an unused result included).
  const auto compute = compileStage(kSpv_compute_memory_model_comp, spv::ExecutionModelGLCompute, true);
  ASSERT_TRUE(compute);
  EXPECT_FALSE(compute->ray.checksPendingAdds);
}

TEST(SpirvCombinedAdds, PipelinesAskForItWhereAStageHasSuchAnAdd) {
  EXPECT_TRUE(spirv::hasCombinableAdds(kSpv_combined_adds_rgen, std::size(kSpv_combined_adds_rgen)));
  EXPECT_TRUE(spirv::hasCombinableAdds(kSpv_combined_adds_rahit, std::size(kSpv_combined_adds_rahit)));
  EXPECT_TRUE(
      spirv::hasCombinableAdds(kSpv_combined_adds_sub_spv14_spvasm, std::size(kSpv_combined_adds_sub_spv14_spvasm)));
  EXPECT_FALSE(spirv::hasCombinableAdds(kSpv_trace_raygen_rgen, std::size(kSpv_trace_raygen_rgen))) << "no atomics";
  EXPECT_TRUE(spirv::hasCombinableAdds(kSpv_compute_memory_model_comp, std::size(kSpv_compute_memory_model_comp)))
      << "one relaxed add of unused result among ordered ones (the scan does not look at the stage)";
  const uint32_t garbage[3] = {1, 2, 3};
  EXPECT_FALSE(spirv::hasCombinableAdds(garbage, 3));
}

TEST(SpirvCombinedAdds, EveryModeLeavesTheMemoryItLeavesWithoutATable) {
  for (uint32_t mode = 0; mode <= 9; ++mode) {
    SCOPED_TRACE("mode " + std::to_string(mode));
    Launch combined, plain;
    launch(raygen(), mode, true, combined, 6);
    launch(raygen(), mode, false, plain, 6);
    abi::flushPendingAdds(&combined.table);
    EXPECT_EQ(std::memcmp(&combined.words, &plain.words, sizeof(Words)), 0);
    EXPECT_EQ(plain.flushes, 0);
  }
}

}  // namespace
}  // namespace vkrt::testing
