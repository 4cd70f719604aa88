// Concurrency and load: threads that each create and destroy compute pipelines, record, submit to every queue (one
// mutex per queue: vkQueueSubmit is externally synchronized on its queue) and wait with timeouts, for a fixed number
// of iterations. Every submission must complete within the timeout (no deadlock, no lost completion) and write what
// its push constants say; the sanitizer builds check for leaks and races.
#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "compute_fill.comp.spv.h"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr uint32_t kQueues = 4;
constexpr uint32_t kThreads = 8;
constexpr uint32_t kIterations = 50;
constexpr uint32_t kCount = 256;                             // elements each dispatch writes
constexpr uint64_t kTimeoutNs = 30ull * 1000 * 1000 * 1000;  // a wait this long is a deadlock

class StressTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.queueCount = kQueues;
    return o;
  }
};

TEST_F(StressTest, ThreadsCreatePipelinesAndSubmitToEveryQueue) {
  std::array<VkQueue, kQueues> queues{};
  std::array<std::mutex, kQueues> queueMutex;
  for (uint32_t q = 0; q < kQueues; ++q) vkGetDeviceQueue(device, 0, q, &queues[q]);

  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dl.bindingCount = 1;
  dl.pBindings = &binding;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDescriptorSetLayout(device, &dl, nullptr, &setLayout), VK_SUCCESS);
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, 8};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &setLayout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreatePipelineLayout(device, &pl, nullptr, &layout), VK_SUCCESS);
  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = sizeof(kSpv_compute_fill_comp);
  sm.pCode = kSpv_compute_fill_comp;
  VkShaderModule module = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateShaderModule(device, &sm, nullptr, &module), VK_SUCCESS);

  std::atomic<uint32_t> completed{0};
  std::vector<std::string> failures(kThreads);
  auto worker = [&](uint32_t t) {
    auto fail = [&](const std::string& what) {
      if (failures[t].empty()) failures[t] = what;
    };
    HostBuffer out = createHostBuffer(kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &size;
    VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    if (vkCreateCommandPool(device, &cp, nullptr, &pool) != VK_SUCCESS ||
        vkCreateDescriptorPool(device, &dp, nullptr, &descriptorPool) != VK_SUCCESS ||
        vkCreateFence(device, &fci, nullptr, &fence) != VK_SUCCESS)
      return fail("object creation failed");
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = descriptorPool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &setLayout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    if (vkAllocateDescriptorSets(device, &da, &set) != VK_SUCCESS) return fail("vkAllocateDescriptorSets failed");
    VkDescriptorBufferInfo bi{out.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    if (vkAllocateCommandBuffers(device, &ai, &cb) != VK_SUCCESS) return fail("vkAllocateCommandBuffers failed");

    for (uint32_t i = 0; i < kIterations && failures[t].empty(); ++i) {
      VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
      ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      ci.stage.module = module;
      ci.stage.pName = "main";
      ci.layout = layout;
      VkPipeline pipeline = VK_NULL_HANDLE;
      if (vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline) != VK_SUCCESS)
        return fail("vkCreateComputePipelines failed");
      std::memset(out.data, 0, kCount * 4);
      VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      vkBeginCommandBuffer(cb, &begin);
      vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
      vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
      const uint32_t push[2] = {t + 1, i * 1000 + 7};
      vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 8, push);
      vkCmdDispatch(cb, kCount / 64, 1, 1);
      vkEndCommandBuffer(cb);
      const uint32_t q = (t + i) % kQueues;
      VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      si.commandBufferCount = 1;
      si.pCommandBuffers = &cb;
      VkResult r;
      {
        std::lock_guard lock(queueMutex[q]);
        r = vkQueueSubmit(queues[q], 1, &si, fence);
      }
      if (r != VK_SUCCESS) return fail("vkQueueSubmit failed");
      r = vkWaitForFences(device, 1, &fence, VK_TRUE, kTimeoutNs);
      if (r != VK_SUCCESS)
        return fail("thread " + std::to_string(t) + " iteration " + std::to_string(i) + ": vkWaitForFences returned " +
                    std::to_string(r));
      vkResetFences(device, 1, &fence);
      vkDestroyPipeline(device, pipeline, nullptr);
      const uint32_t* v = static_cast<const uint32_t*>(out.data);
      for (uint32_t k = 0; k < kCount; ++k)
        if (v[k] != k * push[0] + push[1])
          return fail("thread " + std::to_string(t) + " iteration " + std::to_string(i) + ": element " +
                      std::to_string(k) + " is " + std::to_string(v[k]));
      vkResetCommandBuffer(cb, 0);
      completed.fetch_add(1);
    }
    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyDescriptorPool(device, descriptorPool, nullptr);
    destroy(out);
  };
  std::vector<std::thread> threads;
  for (uint32_t t = 0; t < kThreads; ++t) threads.emplace_back(worker, t);
  for (std::thread& th : threads) th.join();
  for (uint32_t t = 0; t < kThreads; ++t) EXPECT_TRUE(failures[t].empty()) << failures[t];
  EXPECT_EQ(completed.load(), kThreads * kIterations);
  for (VkQueue q : queues) EXPECT_EQ(vkQueueWaitIdle(q), VK_SUCCESS);

  vkDestroyShaderModule(device, module, nullptr);
  vkDestroyPipelineLayout(device, layout, nullptr);
  vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
}

class StressMisuseTest : public StressTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = StressTest::options();
    o.validation = false;  // the layer reports the same misuse
    return o;
  }
};

// Threads destroy the buffer and free the memory of a fill that waits on a semaphore, then let it run: every
// destruction is reported once and deferred to a queue worker, every submission completes in time.
TEST_F(StressMisuseTest, ThreadsDestroyWhatTheirPendingWorkUses) {
  constexpr uint32_t kMisuseThreads = 4, kMisuseIterations = 20;
  std::array<VkQueue, kQueues> queues{};
  std::array<std::mutex, kQueues> queueMutex;
  for (uint32_t q = 0; q < kQueues; ++q) vkGetDeviceQueue(device, 0, q, &queues[q]);
  std::vector<std::string> failures(kMisuseThreads);
  auto worker = [&](uint32_t t) {
    auto fail = [&](const std::string& what) {
      if (failures[t].empty()) failures[t] = what;
    };
    VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &tci};
    VkSemaphore sem = VK_NULL_HANDLE;
    if (vkCreateCommandPool(device, &cp, nullptr, &pool) != VK_SUCCESS ||
        vkCreateFence(device, &fci, nullptr, &fence) != VK_SUCCESS ||
        vkCreateSemaphore(device, &sci, nullptr, &sem) != VK_SUCCESS)
      return fail("object creation failed");
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    if (vkAllocateCommandBuffers(device, &ai, &cb) != VK_SUCCESS) return fail("vkAllocateCommandBuffers failed");
    for (uint32_t i = 0; i < kMisuseIterations && failures[t].empty(); ++i) {
      HostBuffer b = createHostBuffer(4096, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
      VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      vkBeginCommandBuffer(cb, &begin);
      vkCmdFillBuffer(cb, b.buffer, 0, VK_WHOLE_SIZE, i);
      vkEndCommandBuffer(cb);
      const uint64_t waitValue = i + 1;
      VkTimelineSemaphoreSubmitInfo tl{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
      tl.waitSemaphoreValueCount = 1;
      tl.pWaitSemaphoreValues = &waitValue;
      VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
      VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, &tl};
      si.waitSemaphoreCount = 1;
      si.pWaitSemaphores = &sem;
      si.pWaitDstStageMask = &stage;
      si.commandBufferCount = 1;
      si.pCommandBuffers = &cb;
      const uint32_t q = (t + i) % kQueues;
      VkResult r;
      {
        std::lock_guard lock(queueMutex[q]);
        r = vkQueueSubmit(queues[q], 1, &si, fence);
      }
      if (r != VK_SUCCESS) return fail("vkQueueSubmit failed");
      vkDestroyBuffer(device, b.buffer, nullptr);
      vkFreeMemory(device, b.memory, nullptr);
      VkSemaphoreSignalInfo sig{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
      sig.semaphore = sem;
      sig.value = waitValue;
      if (vkSignalSemaphore(device, &sig) != VK_SUCCESS) return fail("vkSignalSemaphore failed");
      r = vkWaitForFences(device, 1, &fence, VK_TRUE, kTimeoutNs);
      if (r != VK_SUCCESS)
        return fail("thread " + std::to_string(t) + " iteration " + std::to_string(i) + ": vkWaitForFences returned " +
                    std::to_string(r));
      vkResetFences(device, 1, &fence);
    }
    vkDestroySemaphore(device, sem, nullptr);
    vkDestroyFence(device, fence, nullptr);
    vkDestroyCommandPool(device, pool, nullptr);
  };
  std::vector<std::thread> threads;
  for (uint32_t t = 0; t < kMisuseThreads; ++t) threads.emplace_back(worker, t);
  for (std::thread& th : threads) th.join();
  for (uint32_t t = 0; t < kMisuseThreads; ++t) EXPECT_TRUE(failures[t].empty()) << failures[t];
  for (VkQueue q : queues) EXPECT_EQ(vkQueueWaitIdle(q), VK_SUCCESS);
  uint32_t buffers = 0, memories = 0, others = 0;
  for (const Message& m : vkrtMessages()) {
    if (m.idName == "VUID-vkDestroyBuffer-buffer-00922") {
      ++buffers;
    } else if (m.idName == "VUID-vkFreeMemory-memory-00677") {
      ++memories;
    } else {
      ++others;
      ADD_FAILURE() << m.text;
    }
  }
  clearMessages();
  EXPECT_EQ(buffers, kMisuseThreads * kMisuseIterations);
  EXPECT_EQ(memories, kMisuseThreads * kMisuseIterations);
  EXPECT_EQ(others, 0u);
}

}  // namespace
}  // namespace vkrt::test
