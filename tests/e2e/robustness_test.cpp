// Robustness: objects destroyed or freed while a submitted command buffer that uses them is pending (reported by
// VUID; the pending work still runs on valid storage), dispatches that read descriptors never written.
#include <cstring>
#include <vector>

#include "compute_fill.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

constexpr VkBufferUsageFlags kXfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

class RobustnessMisuseTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;  // the layer reports the same misuse
    return o;
  }
  VkSemaphore timeline() {
    VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &tci};
    VkSemaphore s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(device, &ci, nullptr, &s), VK_SUCCESS);
    return s;
  }
  VkFence fence() {
    VkFenceCreateInfo ci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFence(device, &ci, nullptr, &f), VK_SUCCESS);
    return f;
  }
  // Submits `cb` waiting for `sem` to reach 1, signalling `f`.
  void submitWaiting(VkCommandBuffer cb, VkSemaphore sem, VkFence f) {
    uint64_t one = 1;
    VkTimelineSemaphoreSubmitInfo tl{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    tl.waitSemaphoreValueCount = 1;
    tl.pWaitSemaphoreValues = &one;
    VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, &tl};
    si.waitSemaphoreCount = 1;
    si.pWaitSemaphores = &sem;
    si.pWaitDstStageMask = &stage;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, f), VK_SUCCESS);
  }
  void signal(VkSemaphore sem) {
    VkSemaphoreSignalInfo s{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
    s.semaphore = sem;
    s.value = 1;
    ASSERT_EQ(vkSignalSemaphore(device, &s), VK_SUCCESS);
  }
  // The VUIDs of vkrt's messages since the last clear, in order; clears.
  std::vector<std::string> vkrtVuids() {
    std::vector<std::string> ids;
    for (const Message& m : vkrtMessages()) ids.push_back(m.idName);
    clearMessages();
    return ids;
  }
};

// A copy waits on a semaphore while its source buffer, the source's memory and its destination buffer are
// destroyed: each is reported, and the copy still runs on the original storage once the semaphore is signaled.
TEST_F(RobustnessMisuseTest, BufferAndMemoryDestroyedWhilePendingStayAliveUntilTheWorkCompletes) {
  constexpr VkDeviceSize kSize = 4096;
  HostBuffer src = createHostBuffer(kSize, kXfer);
  HostBuffer dst = createHostBuffer(kSize, kXfer);
  for (uint32_t i = 0; i < kSize / 4; ++i) static_cast<uint32_t*>(src.data)[i] = i * 2654435761u;
  std::memset(dst.data, 0, kSize);
  std::vector<uint8_t> expected(static_cast<uint8_t*>(src.data), static_cast<uint8_t*>(src.data) + kSize);

  VkCommandBuffer cb = beginOneTime();
  VkBufferCopy region{0, 0, kSize};
  vkCmdCopyBuffer(cb, src.buffer, dst.buffer, 1, &region);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkSemaphore sem = timeline();
  VkFence f = fence();
  submitWaiting(cb, sem, f);

  vkDestroyBuffer(device, src.buffer, nullptr);
  expectVkrtMessage("VUID-vkDestroyBuffer-buffer-00922");
  vkFreeMemory(device, src.memory, nullptr);  // mapped: freeing unmaps it
  expectVkrtMessage("VUID-vkFreeMemory-memory-00677");
  vkDestroyBuffer(device, dst.buffer, nullptr);
  expectVkrtMessage("VUID-vkDestroyBuffer-buffer-00922");
  // The destroyed handles are no longer live: destroying one again is reported as such.
  vkDestroyBuffer(device, src.buffer, nullptr);
  expectVkrtMessage("VUID-vkDestroyBuffer-buffer-parameter");

  signal(sem);
  ASSERT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, 5'000'000'000ull), VK_SUCCESS);
  EXPECT_EQ(std::memcmp(dst.data, expected.data(), kSize), 0);
  EXPECT_TRUE(vkrtVuids().empty());
  vkFreeMemory(device, dst.memory, nullptr);  // nothing pending now: no report
  EXPECT_TRUE(vkrtVuids().empty());
  vkDestroyFence(device, f, nullptr);
  vkDestroySemaphore(device, sem, nullptr);
}

// A dispatch waits on a semaphore while its pipeline, its descriptor pool (and with it the set) and the buffer
// the set points at are destroyed: each is reported and the dispatch still writes the buffer's memory.
TEST_F(RobustnessMisuseTest, PipelineAndDescriptorsDestroyedWhilePendingStayAliveUntilTheWorkCompletes) {
  constexpr uint32_t kCount = 256;
  HostBuffer out = createHostBuffer(kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0, kCount * 4);
  ComputePipeline p = makeComputePipelineWithArrays(device, kSpv_compute_fill_comp, sizeof(kSpv_compute_fill_comp),
                                                    {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, 8);
  ASSERT_EQ(p.result, VK_SUCCESS);
  VkDescriptorBufferInfo bi{out.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = p.set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);

  VkCommandBuffer cb = beginOneTime();
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  uint32_t push[2] = {3, 7};
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 8, push);
  vkCmdDispatch(cb, kCount / 64, 1, 1);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkSemaphore sem = timeline();
  VkFence f = fence();
  submitWaiting(cb, sem, f);

  vkDestroyPipeline(device, p.pipeline, nullptr);
  expectVkrtMessage("VUID-vkDestroyPipeline-pipeline-00765");
  vkDestroyDescriptorPool(device, p.pool, nullptr);
  expectVkrtMessage("VUID-vkDestroyDescriptorPool-descriptorPool-00303");
  // The buffer is reached through the set only: not a direct reference of the command buffer, so not reported,
  // but its destruction waits for the pending work all the same.
  vkDestroyBuffer(device, out.buffer, nullptr);
  EXPECT_TRUE(vkrtVuids().empty());
  // Layouts and shader modules may be destroyed once used (maintenance4): nothing to report.
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  EXPECT_TRUE(vkrtVuids().empty());

  signal(sem);
  ASSERT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, 5'000'000'000ull), VK_SUCCESS);
  const uint32_t* v = static_cast<const uint32_t*>(out.data);
  for (uint32_t i = 0; i < kCount; ++i) ASSERT_EQ(v[i], i * 3 + 7) << "element " << i;
  EXPECT_TRUE(vkrtVuids().empty());
  vkFreeMemory(device, out.memory, nullptr);
  vkDestroyFence(device, f, nullptr);
  vkDestroySemaphore(device, sem, nullptr);
}

// A command buffer whose commands refer to a buffer destroyed since they were recorded is invalid: submitting it is
// reported and refused (it used to run, and read the destroyed buffer), also once another buffer has been created,
// possibly at the destroyed one's address.
TEST_F(RobustnessMisuseTest, ACommandBufferReferringToADestroyedBufferIsNotSubmitted) {
  constexpr VkDeviceSize kSize = 256;
  HostBuffer src = createHostBuffer(kSize, kXfer);
  HostBuffer dst = createHostBuffer(kSize, kXfer);
  VkCommandBuffer cb = beginOneTime();
  VkBufferCopy region{0, 0, kSize};
  vkCmdCopyBuffer(cb, src.buffer, dst.buffer, 1, &region);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  vkDestroyBuffer(device, src.buffer, nullptr);
  EXPECT_TRUE(vkrtVuids().empty());  // nothing pending: destroyed at once
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00070");
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = kSize;
  bci.usage = kXfer;
  VkBuffer again = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &again), VK_SUCCESS);
  EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00070");
  EXPECT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  vkDestroyBuffer(device, again, nullptr);
  vkFreeMemory(device, src.memory, nullptr);
  destroy(dst);
  EXPECT_TRUE(vkrtVuids().empty());
}

// A dispatch whose pipeline uses a descriptor never written is reported once, naming the set, binding and
// element; a binding the shader does not use may stay unwritten, and once written the dispatch is silent.
TEST_F(RobustnessMisuseTest, DispatchReadingADescriptorNeverWrittenIsReported) {
  constexpr uint32_t kCount = 64;
  HostBuffer out = createHostBuffer(kCount * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(out.data, 0xAB, kCount * 4);
  // Binding 0 is the shader's output; binding 1 is not used by it.
  ComputePipeline p =
      makeComputePipelineWithArrays(device, kSpv_compute_fill_comp, sizeof(kSpv_compute_fill_comp),
                                    {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}}, 8);
  ASSERT_EQ(p.result, VK_SUCCESS);
  auto dispatch = [&] {
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    uint32_t push[2] = {1, 5};
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 8, push);
    vkCmdDispatch(cb, 1, 1, 1);
    vkCmdDispatch(cb, 1, 1, 1);
    submitAndWait(cb);  // ends the command buffer
  };
  dispatch();
  std::vector<Message> msgs = vkrtMessages();
  clearMessages();
  ASSERT_EQ(msgs.size(), 2u);  // once per dispatch command
  for (const Message& m : msgs) {
    EXPECT_EQ(m.idName, "VUID-vkCmdDispatch-None-08114");
    EXPECT_NE(m.text.find("set 0 binding 0"), std::string::npos) << m.text;
    EXPECT_NE(m.text.find("element 0"), std::string::npos) << m.text;
  }
  // Nothing was written: the unwritten descriptor has no storage behind it.
  for (uint32_t i = 0; i < kCount; ++i) ASSERT_EQ(static_cast<const uint32_t*>(out.data)[i], 0xABABABABu);

  VkDescriptorBufferInfo bi{out.buffer, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = p.set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
  dispatch();
  EXPECT_TRUE(vkrtVuids().empty());  // binding 1 is still unwritten, but unused
  for (uint32_t i = 0; i < kCount; ++i) ASSERT_EQ(static_cast<const uint32_t*>(out.data)[i], i + 5);

  vkDestroyPipeline(device, p.pipeline, nullptr);
  vkDestroyShaderModule(device, p.module, nullptr);
  vkDestroyDescriptorPool(device, p.pool, nullptr);
  vkDestroyPipelineLayout(device, p.layout, nullptr);
  vkDestroyDescriptorSetLayout(device, p.setLayout, nullptr);
  destroy(out);
}

}  // namespace
}  // namespace vkrt::test
