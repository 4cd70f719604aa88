// The thread pool, and compute pipelines' per-device sharing of compiled shaders (below the loader, so that
// the compile counter can be read).
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "compute_control.comp.spv.h"
#include "compute_push_spec.comp.spv.h"
#include "exec/thread_pool.hpp"
#include "runtime/alloc.hpp"
#include "runtime/compute_pipeline.hpp"
#include "runtime/device.hpp"
#include "runtime/instance.hpp"
#include "runtime/physical_device.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

TEST(ThreadPool, EveryIndexRunsOnceOverSeveralWorkers) {
  exec::ThreadPool pool(3);
  const uint64_t n = 10000;
  std::vector<std::atomic<int>> hits(n);
  std::mutex m;
  std::set<std::thread::id> threads;
  std::set<unsigned> workers;
  pool.parallelFor(n, [&](uint64_t i, unsigned w) {
    hits[i].fetch_add(1);
    if (i % 97 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
    std::lock_guard<std::mutex> lock(m);
    threads.insert(std::this_thread::get_id());
    workers.insert(w);
    EXPECT_LT(w, pool.workerSlots());
  });
  for (uint64_t i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << i;
  EXPECT_GT(threads.size(), 1u);
  EXPECT_EQ(threads.size(), workers.size()) << "one worker index per thread";
  // Concurrent callers are served one after the other, each to completion.
  std::atomic<uint64_t> total{0};
  std::vector<std::thread> callers;
  for (int c = 0; c < 4; ++c)
    callers.emplace_back([&] { pool.parallelFor(500, [&](uint64_t, unsigned) { total.fetch_add(1); }); });
  for (auto& t : callers) t.join();
  EXPECT_EQ(total.load(), 2000u);
  pool.parallelFor(0, [&](uint64_t, unsigned) { ADD_FAILURE() << "no index to run"; });
}

// runConcurrently (pipeline stages): every index once, spread over threads, and not serialized behind a running
// parallelFor: a caller makes progress on its own while the workers are busy with another job.
TEST(ThreadPool, RunConcurrentlyIsNotSerializedBehindParallelFor) {
  exec::ThreadPool pool(3);
  std::vector<std::atomic<int>> hits(64);
  std::mutex m;
  std::set<std::thread::id> threads;
  pool.runConcurrently(hits.size(), [&](uint64_t i) {
    hits[i].fetch_add(1);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    std::lock_guard<std::mutex> lock(m);
    threads.insert(std::this_thread::get_id());
  });
  for (size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << i;
  EXPECT_GT(threads.size(), 1u);
  // A parallelFor whose every index waits until the concurrent run below has finished: with runConcurrently
  // queued behind it (or serialized like parallelFor) this would never end.
  std::atomic<bool> released{false};
  std::thread busy([&] {
    pool.parallelFor(4, [&](uint64_t, unsigned) {
      while (!released.load()) std::this_thread::sleep_for(std::chrono::microseconds(100));
    });
  });
  std::atomic<uint64_t> ran{0};
  pool.runConcurrently(10, [&](uint64_t) { ran.fetch_add(1); });
  EXPECT_EQ(ran.load(), 10u);
  released = true;
  busy.join();
}

// Idle workers watch for the next job before they sleep: back-to-back jobs are taken without a wake-up, every index
// still once; with no spin time they sleep at once; and a pool whose workers are watching is destroyed without
// waiting out their spin time.
TEST(ThreadPool, WatchingWorkersTakeBackToBackJobsWithoutSleeping) {
  constexpr unsigned kLongSpin = 5'000'000;  // 5 s: longer than the jobs below take even under a sanitizer
  auto jobs = [](exec::ThreadPool& pool) {
    for (int j = 0; j < 50; ++j) {
      std::vector<std::atomic<int>> hits(64);
      pool.parallelFor(hits.size(), [&](uint64_t i, unsigned w) {
        hits[i].fetch_add(1);
        EXPECT_LT(w, pool.workerSlots());
      });
      for (size_t i = 0; i < hits.size(); ++i) ASSERT_EQ(hits[i].load(), 1) << "job " << j << " index " << i;
    }
  };
  const auto start = std::chrono::steady_clock::now();
  {
    exec::ThreadPool pool(3, kLongSpin);
    jobs(pool);
    std::atomic<uint64_t> ran{0};
    std::vector<std::thread> callers;
    for (int c = 0; c < 3; ++c)
      callers.emplace_back([&] { pool.runConcurrently(20, [&](uint64_t) { ran.fetch_add(1); }); });
    for (auto& t : callers) t.join();
    EXPECT_EQ(ran.load(), 60u);
    EXPECT_EQ(pool.sleeps(), 0u) << "a worker slept although it was watching";
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::microseconds(kLongSpin))
      << "the destructor waited for the watching workers' spin time";

  exec::ThreadPool sleepy(3, 0);
  jobs(sleepy);
  // With no spin time every worker that finds no job sleeps (at least once, at its start).
  for (int i = 0; i < 1000 && sleepy.sleeps() < 3; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_GE(sleepy.sleeps(), 3u);
}

class ComputePipelineSharing : public ::testing::Test {
 protected:
  void SetUp() override {
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ASSERT_EQ(vkrt_CreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    ASSERT_EQ(vkrt_EnumeratePhysicalDevices(instance, &n, &pd), VK_SUCCESS);
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dev = createObject<Device>(nullptr, VK_SYSTEM_ALLOCATION_SCOPE_DEVICE, fromHandle<PhysicalDevice>(pd), dci);
    ASSERT_NE(dev, nullptr);
    device = toHandle(dev);
    VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 1;
    dl.pBindings = &b;
    ASSERT_EQ(vkrt_CreateDescriptorSetLayout(device, &dl, nullptr, &setLayout), VK_SUCCESS);
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, 32};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    ASSERT_EQ(vkrt_CreatePipelineLayout(device, &pl, nullptr, &layout), VK_SUCCESS);
  }
  void TearDown() override {
    vkrt_DestroyPipelineLayout(device, layout, nullptr);
    vkrt_DestroyDescriptorSetLayout(device, setLayout, nullptr);
    destroyObject(dev, nullptr);
    vkrt_DestroyInstance(instance, nullptr);
  }
  VkResult create(const uint32_t* words, size_t bytes, VkPipeline* out, const VkSpecializationInfo* spec = nullptr,
                  VkPipelineCreateFlags flags = 0) {
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = bytes;
    sm.pCode = words;
    // The stage's module comes chained (no VkShaderModule): sharing is by content, not by module object.
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.flags = flags;
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, &sm};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = spec;
    ci.layout = layout;
    return vkrt_CreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, out);
  }

  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice pd = VK_NULL_HANDLE;
  Device* dev = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
};

TEST_F(ComputePipelineSharing, OneCompilationPerShaderKeyPerDevice) {
  VkPipeline a = VK_NULL_HANDLE, b = VK_NULL_HANDLE, c = VK_NULL_HANDLE, d = VK_NULL_HANDLE;
  // Nothing compiled yet: a pipeline that may not compile reports VK_PIPELINE_COMPILE_REQUIRED.
  EXPECT_EQ(create(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, &a, nullptr,
                   VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT),
            VK_PIPELINE_COMPILE_REQUIRED);
  EXPECT_EQ(a, VK_NULL_HANDLE);
  uint64_t before = shaderCompileCount();
  ASSERT_EQ(create(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, &a), VK_SUCCESS);
  EXPECT_EQ(shaderCompileCount(), before + 1);
  ASSERT_EQ(create(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, &b, nullptr,
                   VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT),
            VK_SUCCESS);
  EXPECT_EQ(shaderCompileCount(), before + 1) << "the second pipeline shares the first one's code";
  EXPECT_EQ(static_cast<ComputePipeline*>(fromHandle<Pipeline>(a))->shader,
            static_cast<ComputePipeline*>(fromHandle<Pipeline>(b))->shader);
  // Different specialization data is a different shader.
  uint32_t size = 4;
  VkSpecializationMapEntry e{0, 0, 4};
  VkSpecializationInfo spec{1, &e, 4, &size};
  ASSERT_EQ(create(kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, &c, &spec), VK_SUCCESS);
  size = 8;
  ASSERT_EQ(create(kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, &d, &spec), VK_SUCCESS);
  EXPECT_EQ(shaderCompileCount(), before + 3);
  EXPECT_EQ(static_cast<ComputePipeline*>(fromHandle<Pipeline>(c))->shader->localSize[0], 4u);
  EXPECT_EQ(static_cast<ComputePipeline*>(fromHandle<Pipeline>(d))->shader->localSize[0], 8u);
  for (VkPipeline p : {a, b, c, d}) vkrt_DestroyPipeline(device, p, nullptr);
  // Once no pipeline uses it, the code is released; the next pipeline compiles again.
  VkPipeline e2 = VK_NULL_HANDLE;
  ASSERT_EQ(create(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, &e2), VK_SUCCESS);
  EXPECT_EQ(shaderCompileCount(), before + 4);
  vkrt_DestroyPipeline(device, e2, nullptr);
}

TEST_F(ComputePipelineSharing, ConcurrentCreationCompilesEachShaderOnce) {
  uint64_t before = shaderCompileCount();
  std::vector<VkPipeline> pipelines(8, VK_NULL_HANDLE);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < pipelines.size(); ++t) {
    threads.emplace_back([&, t] {
      if (t % 2) {
        EXPECT_EQ(create(kSpv_compute_control_comp, sizeof kSpv_compute_control_comp, &pipelines[t]), VK_SUCCESS);
      } else {
        EXPECT_EQ(create(kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, &pipelines[t]), VK_SUCCESS);
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(shaderCompileCount(), before + 2);
  for (VkPipeline p : pipelines) vkrt_DestroyPipeline(device, p, nullptr);
}

TEST_F(ComputePipelineSharing, SpecializationMapEntryOutOfRangeIsReported) {
  uint32_t v = 4;
  VkSpecializationMapEntry e{0, 2, 4};
  VkSpecializationInfo spec{1, &e, 4, &v};
  VkPipeline p = VK_NULL_HANDLE;
  EXPECT_EQ(create(kSpv_compute_push_spec_comp, sizeof kSpv_compute_push_spec_comp, &p, &spec),
            VK_ERROR_VALIDATION_FAILED_EXT);
  EXPECT_EQ(p, VK_NULL_HANDLE);
}

}  // namespace
}  // namespace vkrt
