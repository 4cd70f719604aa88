// Command pools and buffers (state machine, primary/secondary, one-time and simultaneous use), transfer
// commands (bytes compared), binding-state commands, debug labels, and misuse reported by VUID.
#include <cstring>
#include <vector>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

class CommandsTest : public VulkanTest {
 protected:
  static constexpr VkBufferUsageFlags kXfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

  VkCommandBuffer allocate(VkCommandBufferLevel level, VkCommandPool pool = VK_NULL_HANDLE) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool ? pool : commandPool;
    ai.level = level;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateCommandBuffers(device, &ai, &cb), VK_SUCCESS);
    return cb;
  }
  VkResult begin(VkCommandBuffer cb, VkCommandBufferUsageFlags flags, bool secondary = false) {
    VkCommandBufferInheritanceInfo inh{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = flags;
    bi.pInheritanceInfo = secondary ? &inh : nullptr;
    return vkBeginCommandBuffer(cb, &bi);
  }
  VkResult submit(VkCommandBuffer cb, VkFence fence = VK_NULL_HANDLE) {
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    return vkQueueSubmit(queue, 1, &si, fence);
  }
  VkCommandPool createPool(VkCommandPoolCreateFlags flags) {
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.flags = flags;
    VkCommandPool p = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateCommandPool(device, &ci, nullptr, &p), VK_SUCCESS);
    return p;
  }
  static uint32_t word(const HostBuffer& b, size_t i) {
    uint32_t v;
    std::memcpy(&v, static_cast<const uint8_t*>(b.data) + 4 * i, 4);
    return v;
  }
  static void bufferBarrier(VkCommandBuffer cb, VkBuffer buf) {
    VkBufferMemoryBarrier2 b{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    b.srcStageMask = b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
    b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.buffer = buf;
    b.size = VK_WHOLE_SIZE;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.bufferMemoryBarrierCount = 1;
    dep.pBufferMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cb, &dep);
  }
  static void transferBarrier(VkCommandBuffer cb) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                         nullptr);
  }
};

TEST_F(CommandsTest, FillUpdateAndCopyProduceTheExpectedBytes) {
  HostBuffer a = createHostBuffer(1022, kXfer);
  HostBuffer b = createHostBuffer(1024, kXfer);
  std::memset(a.data, 0x11, 1022);
  std::memset(b.data, 0x22, 1024);
  std::vector<uint32_t> update(16);
  for (uint32_t i = 0; i < 16; ++i) update[i] = 0x1000 + i;

  VkCommandBuffer cb = beginOneTime();
  vkCmdFillBuffer(cb, a.buffer, 8, VK_WHOLE_SIZE, 0xdeadbeef);  // bytes 8..1019: 1022-8 rounded down to 4
  transferBarrier(cb);
  vkCmdUpdateBuffer(cb, a.buffer, 64, 64, update.data());
  bufferBarrier(cb, a.buffer);
  VkBufferCopy regions[2] = {{64, 0, 64}, {0, 512, 16}};
  vkCmdCopyBuffer(cb, a.buffer, b.buffer, 2, regions);
  transferBarrier(cb);
  VkBufferCopy2 r2{VK_STRUCTURE_TYPE_BUFFER_COPY_2};
  r2.srcOffset = 1016;
  r2.dstOffset = 1000;
  r2.size = 6;
  VkCopyBufferInfo2 ci{VK_STRUCTURE_TYPE_COPY_BUFFER_INFO_2};
  ci.srcBuffer = a.buffer;
  ci.dstBuffer = b.buffer;
  ci.regionCount = 1;
  ci.pRegions = &r2;
  vkCmdCopyBuffer2(cb, &ci);
  update[0] = 0xabcdef01;  // the command keeps its own copy of the data
  submitAndWait(cb);

  const uint8_t* pa = static_cast<const uint8_t*>(a.data);
  const uint8_t* pb = static_cast<const uint8_t*>(b.data);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(pa[i], 0x11) << i;
  for (size_t i = 2; i < 16; ++i) EXPECT_EQ(word(a, i), 0xdeadbeefu) << i;
  for (size_t i = 0; i < 16; ++i) EXPECT_EQ(word(a, 16 + i), 0x1000u + i) << i;
  for (size_t i = 32; i < 255; ++i) EXPECT_EQ(word(a, i), 0xdeadbeefu) << i;
  EXPECT_EQ(pa[1020], 0x11);
  EXPECT_EQ(pa[1021], 0x11);
  for (size_t i = 0; i < 16; ++i) EXPECT_EQ(word(b, i), 0x1000u + i) << i;
  for (int i = 64; i < 512; ++i) ASSERT_EQ(pb[i], 0x22) << i;
  EXPECT_EQ(word(b, 128), 0x11111111u);
  EXPECT_EQ(word(b, 129), 0x11111111u);
  EXPECT_EQ(word(b, 130), 0xdeadbeefu);
  EXPECT_EQ(word(b, 131), 0xdeadbeefu);
  const uint8_t tail[6] = {0xef, 0xbe, 0xad, 0xde, 0x11, 0x11};
  EXPECT_EQ(std::memcmp(pb + 1000, tail, 6), 0);
  EXPECT_EQ(pb[1006], 0x22);
  destroy(a);
  destroy(b);
}

TEST_F(CommandsTest, SecondaryCommandBuffersRunInlineInOrder) {
  HostBuffer x = createHostBuffer(256, kXfer);
  HostBuffer y = createHostBuffer(256, kXfer);
  std::memset(x.data, 0, 256);
  std::memset(y.data, 0, 256);
  VkCommandBuffer s1 = allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  VkCommandBuffer s2 = allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  ASSERT_EQ(begin(s1, 0, true), VK_SUCCESS);
  vkCmdFillBuffer(s1, x.buffer, 0, 256, 0x01010101);
  ASSERT_EQ(vkEndCommandBuffer(s1), VK_SUCCESS);
  ASSERT_EQ(begin(s2, 0, true), VK_SUCCESS);
  const uint32_t two[4] = {2, 2, 2, 2};
  vkCmdUpdateBuffer(s2, x.buffer, 0, 16, two);
  ASSERT_EQ(vkEndCommandBuffer(s2), VK_SUCCESS);

  VkCommandBuffer p = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  ASSERT_EQ(begin(p, 0), VK_SUCCESS);
  vkCmdExecuteCommands(p, 1, &s1);
  transferBarrier(p);
  VkBufferCopy r{0, 0, 256};
  vkCmdCopyBuffer(p, x.buffer, y.buffer, 1, &r);
  transferBarrier(p);
  vkCmdExecuteCommands(p, 1, &s2);
  ASSERT_EQ(vkEndCommandBuffer(p), VK_SUCCESS);
  ASSERT_EQ(submit(p), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  for (size_t i = 0; i < 64; ++i) EXPECT_EQ(word(y, i), 0x01010101u) << i;  // copied between s1 and s2
  for (size_t i = 0; i < 4; ++i) EXPECT_EQ(word(x, i), 2u) << i;
  for (size_t i = 4; i < 64; ++i) EXPECT_EQ(word(x, i), 0x01010101u) << i;

  // Resubmitting executes everything again.
  std::memset(x.data, 0, 256);
  std::memset(y.data, 0, 256);
  ASSERT_EQ(submit(p), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  EXPECT_EQ(word(y, 63), 0x01010101u);
  EXPECT_EQ(word(x, 0), 2u);
  VkCommandBuffer all[3] = {p, s1, s2};
  vkFreeCommandBuffers(device, commandPool, 3, all);
  destroy(x);
  destroy(y);
}

TEST_F(CommandsTest, ResubmissionSeesNewHostDataAndFencesOrderIt) {
  HostBuffer a = createHostBuffer(64, kXfer);
  HostBuffer b = createHostBuffer(64, kXfer);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  ASSERT_EQ(begin(cb, 0), VK_SUCCESS);
  VkBufferCopy r{0, 0, 64};
  vkCmdCopyBuffer(cb, a.buffer, b.buffer, 1, &r);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  ASSERT_EQ(vkCreateFence(device, &fci, nullptr, &fence), VK_SUCCESS);
  for (uint8_t round = 1; round <= 3; ++round) {
    std::memset(a.data, round * 17, 64);
    ASSERT_EQ(submit(cb, fence), VK_SUCCESS);
    ASSERT_EQ(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), VK_SUCCESS);
    ASSERT_EQ(vkResetFences(device, 1, &fence), VK_SUCCESS);
    for (int i = 0; i < 64; ++i) ASSERT_EQ(static_cast<uint8_t*>(b.data)[i], round * 17) << int(round);
  }
  vkDestroyFence(device, fence, nullptr);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  destroy(a);
  destroy(b);
}

TEST_F(CommandsTest, SimultaneousUseRunsEverySubmission) {
  HostBuffer buf = createHostBuffer(64, kXfer);
  const uint32_t init[3] = {10, 11, 12};
  std::memcpy(buf.data, init, sizeof init);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  ASSERT_EQ(begin(cb, VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT), VK_SUCCESS);
  VkBufferCopy c1{0, 4, 4}, c2{8, 0, 4};
  vkCmdCopyBuffer(cb, buf.buffer, buf.buffer, 1, &c1);  // w1 = w0
  transferBarrier(cb);
  vkCmdCopyBuffer(cb, buf.buffer, buf.buffer, 1, &c2);  // w0 = w2
  transferBarrier(cb);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkSubmitInfo si[2] = {{VK_STRUCTURE_TYPE_SUBMIT_INFO}, {VK_STRUCTURE_TYPE_SUBMIT_INFO}};
  for (auto& s : si) {
    s.commandBufferCount = 1;
    s.pCommandBuffers = &cb;
  }
  ASSERT_EQ(vkQueueSubmit(queue, 2, si, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  // Once: {12, 10, 12}; twice: {12, 12, 12}.
  EXPECT_EQ(word(buf, 0), 12u);
  EXPECT_EQ(word(buf, 1), 12u);
  EXPECT_EQ(word(buf, 2), 12u);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  destroy(buf);
}

TEST_F(CommandsTest, PoolResetTrimAndDebugLabelsAreAccepted) {
  VkCommandPool pool = createPool(VK_COMMAND_POOL_CREATE_TRANSIENT_BIT);
  HostBuffer buf = createHostBuffer(64, kXfer);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY, pool);
  auto beginLabel = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkCmdBeginDebugUtilsLabelEXT"));
  auto endLabel =
      reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(vkGetInstanceProcAddr(instance, "vkCmdEndDebugUtilsLabelEXT"));
  auto insertLabel = reinterpret_cast<PFN_vkCmdInsertDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkCmdInsertDebugUtilsLabelEXT"));
  auto qBegin = reinterpret_cast<PFN_vkQueueBeginDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkQueueBeginDebugUtilsLabelEXT"));
  auto qEnd = reinterpret_cast<PFN_vkQueueEndDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkQueueEndDebugUtilsLabelEXT"));
  auto qInsert = reinterpret_cast<PFN_vkQueueInsertDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkQueueInsertDebugUtilsLabelEXT"));
  ASSERT_TRUE(beginLabel && endLabel && insertLabel && qBegin && qEnd && qInsert);
  VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
  label.pLabelName = "fill";

  for (uint32_t round = 0; round < 2; ++round) {
    ASSERT_EQ(begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT), VK_SUCCESS);
    beginLabel(cb, &label);
    insertLabel(cb, &label);
    vkCmdFillBuffer(cb, buf.buffer, 0, VK_WHOLE_SIZE, 100 + round);
    endLabel(cb);
    ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    qBegin(queue, &label);
    qInsert(queue, &label);
    ASSERT_EQ(submit(cb), VK_SUCCESS);
    qEnd(queue);
    ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
    EXPECT_EQ(word(buf, 15), 100 + round);
    // The pool has no RESET_COMMAND_BUFFER flag: resetting the pool is how its buffers are re-recorded.
    ASSERT_EQ(vkResetCommandPool(device, pool, VK_COMMAND_POOL_RESET_RELEASE_RESOURCES_BIT), VK_SUCCESS);
    vkTrimCommandPool(device, pool, 0);
  }
  vkDestroyCommandPool(device, pool, nullptr);  // frees cb too
  destroy(buf);
}

TEST_F(CommandsTest, BindingStateCommandsRecordWithoutComplaint) {
  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, 128};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &range;
  VkPipelineLayout layout;
  ASSERT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &layout), VK_SUCCESS);
  VkCommandBuffer cb = beginOneTime();
  const uint32_t values[32] = {1, 2, 3};
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 128, values);
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 64, 16, values);
  submitAndWait(cb);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyPipelineLayout(device, layout, nullptr);
}

// ---- Misuse: vkrt's own reports (the validation layer is off) ----

class CommandsMisuseTest : public CommandsTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
};

TEST_F(CommandsMisuseTest, StateMachineViolationsAreReported) {
  HostBuffer buf = createHostBuffer(64, kXfer);
  std::memset(buf.data, 0, 64);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  vkCmdFillBuffer(cb, buf.buffer, 0, 64, 7);  // initial state: not recording
  expectVkrtMessage("VUID-vkCmdFillBuffer-commandBuffer-recording");
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkEndCommandBuffer-commandBuffer-00059");
  EXPECT_EQ(submit(cb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00070");
  ASSERT_EQ(begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT), VK_SUCCESS);
  EXPECT_EQ(begin(cb, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkBeginCommandBuffer-commandBuffer-00049");
  vkCmdFillBuffer(cb, buf.buffer, 0, 64, 7);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  vkCmdFillBuffer(cb, buf.buffer, 0, 64, 9);  // executable: not recording either
  expectVkrtMessage("VUID-vkCmdFillBuffer-commandBuffer-recording");
  ASSERT_EQ(submit(cb), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  EXPECT_EQ(word(buf, 15), 7u);
  std::memset(buf.data, 0, 64);
  EXPECT_EQ(submit(cb), VK_ERROR_VALIDATION_FAILED_EXT);  // one-time submit: invalid after execution
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00070");
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  EXPECT_EQ(word(buf, 15), 0u);

  // A primary cannot be both one-time and simultaneous; a secondary needs inheritance info.
  EXPECT_EQ(begin(cb, VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT | VK_COMMAND_BUFFER_USAGE_SIMULTANEOUS_USE_BIT),
            VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkBeginCommandBuffer-commandBuffer-02840");
  VkCommandBuffer sec = allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  EXPECT_EQ(begin(sec, 0, false), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkBeginCommandBuffer-commandBuffer-00051");
  ASSERT_EQ(begin(sec, 0, true), VK_SUCCESS);
  vkCmdFillBuffer(sec, buf.buffer, 0, 64, 5);
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  EXPECT_EQ(submit(sec), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubmitInfo-pCommandBuffers-00075");

  // Executing a primary inside a primary; re-recording a secondary invalidates the primary that executes it.
  VkCommandBuffer other = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  ASSERT_EQ(begin(other, 0), VK_SUCCESS);
  ASSERT_EQ(vkEndCommandBuffer(other), VK_SUCCESS);
  ASSERT_EQ(begin(cb, 0), VK_SUCCESS);
  vkCmdExecuteCommands(cb, 1, &other);
  expectVkrtMessage("VUID-vkCmdExecuteCommands-pCommandBuffers-00088");
  vkCmdExecuteCommands(cb, 1, &sec);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  ASSERT_EQ(begin(sec, 0, true), VK_SUCCESS);
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  EXPECT_EQ(submit(cb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00070");
  VkCommandBuffer all[3] = {cb, sec, other};
  vkFreeCommandBuffers(device, commandPool, 3, all);
  destroy(buf);
}

TEST_F(CommandsMisuseTest, PoolWithoutResetFlagRejectsIndividualResets) {
  VkCommandPool pool = createPool(0);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY, pool);
  ASSERT_EQ(begin(cb, 0), VK_SUCCESS);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  EXPECT_EQ(vkResetCommandBuffer(cb, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkResetCommandBuffer-commandBuffer-00046");
  EXPECT_EQ(begin(cb, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkBeginCommandBuffer-commandBuffer-00050");
  ASSERT_EQ(vkResetCommandPool(device, pool, 0), VK_SUCCESS);
  EXPECT_EQ(begin(cb, 0), VK_SUCCESS);
  vkDestroyCommandPool(device, pool, nullptr);
}

TEST_F(CommandsMisuseTest, PendingCommandBuffersCannotBeFreedOrReset) {
  VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
  tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &tci};
  VkSemaphore sem;
  ASSERT_EQ(vkCreateSemaphore(device, &sci, nullptr, &sem), VK_SUCCESS);
  HostBuffer buf = createHostBuffer(64, kXfer);
  std::memset(buf.data, 0, 64);
  VkCommandBuffer cb = allocate(VK_COMMAND_BUFFER_LEVEL_PRIMARY);
  ASSERT_EQ(begin(cb, 0), VK_SUCCESS);
  vkCmdFillBuffer(cb, buf.buffer, 0, 64, 3);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  uint64_t waitValue = 1;
  VkTimelineSemaphoreSubmitInfo tsi{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  tsi.waitSemaphoreValueCount = 1;
  tsi.pWaitSemaphoreValues = &waitValue;
  VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, &tsi};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &sem;
  si.pWaitDstStageMask = &stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  ASSERT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);  // blocked until the host signals 1
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  expectVkrtMessage("VUID-vkFreeCommandBuffers-pCommandBuffers-00047");
  EXPECT_EQ(vkResetCommandBuffer(cb, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkResetCommandBuffer-commandBuffer-00045");
  EXPECT_EQ(submit(cb), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00071");
  vkDestroySemaphore(device, sem, nullptr);
  expectVkrtMessage("VUID-vkDestroySemaphore-semaphore-01137");
  EXPECT_EQ(word(buf, 0), 0u);
  VkSemaphoreSignalInfo sig{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
  sig.semaphore = sem;
  sig.value = 1;
  ASSERT_EQ(vkSignalSemaphore(device, &sig), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
  EXPECT_EQ(word(buf, 15), 3u);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  vkDestroySemaphore(device, sem, nullptr);
  destroy(buf);
}

TEST_F(CommandsMisuseTest, InvalidTransfersAreReportedAndNotRecorded) {
  HostBuffer a = createHostBuffer(256, kXfer);
  HostBuffer b = createHostBuffer(256, kXfer);
  HostBuffer noSrc = createHostBuffer(256, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  std::memset(a.data, 0xaa, 256);
  std::memset(b.data, 0xbb, 256);
  std::vector<uint8_t> big(65540, 1);
  VkCommandBuffer cb = beginOneTime();
  vkCmdFillBuffer(cb, a.buffer, 2, 8, 0);
  expectVkrtMessage("VUID-vkCmdFillBuffer-dstOffset-00025");
  vkCmdFillBuffer(cb, a.buffer, 256, VK_WHOLE_SIZE, 0);
  expectVkrtMessage("VUID-vkCmdFillBuffer-dstOffset-00024");
  vkCmdFillBuffer(cb, a.buffer, 8, 252, 0);
  expectVkrtMessage("VUID-vkCmdFillBuffer-size-00027");
  vkCmdFillBuffer(cb, a.buffer, 8, 6, 0);
  expectVkrtMessage("VUID-vkCmdFillBuffer-size-00028");
  vkCmdUpdateBuffer(cb, a.buffer, 0, 65540, big.data());
  expectVkrtMessage("VUID-vkCmdUpdateBuffer-dataSize-00037");
  vkCmdUpdateBuffer(cb, a.buffer, 0, 6, big.data());
  expectVkrtMessage("VUID-vkCmdUpdateBuffer-dataSize-00038");
  vkCmdUpdateBuffer(cb, a.buffer, 4, 256, big.data());
  expectVkrtMessage("VUID-vkCmdUpdateBuffer-dataSize-00033");
  vkCmdUpdateBuffer(cb, a.buffer, 2, 4, big.data());
  expectVkrtMessage("VUID-vkCmdUpdateBuffer-dstOffset-00036");
  VkBufferCopy past{200, 0, 64};
  vkCmdCopyBuffer(cb, a.buffer, b.buffer, 1, &past);
  expectVkrtMessage("VUID-vkCmdCopyBuffer-size-00115");
  VkBufferCopy pastDst{0, 255, 2};
  vkCmdCopyBuffer(cb, a.buffer, b.buffer, 1, &pastDst);
  expectVkrtMessage("VUID-vkCmdCopyBuffer-size-00116");
  VkBufferCopy ok{0, 0, 16};
  vkCmdCopyBuffer(cb, noSrc.buffer, b.buffer, 1, &ok);
  expectVkrtMessage("VUID-vkCmdCopyBuffer-srcBuffer-00118");
  VkBufferCopy overlap{0, 8, 16};
  vkCmdCopyBuffer(cb, a.buffer, a.buffer, 1, &overlap);
  expectVkrtMessage("VUID-vkCmdCopyBuffer-pRegions-00117");
  VkBufferCopy zero{0, 0, 0};
  vkCmdCopyBuffer(cb, a.buffer, b.buffer, 1, &zero);
  expectVkrtMessage("VUID-VkBufferCopy-size-01988");
  VkBufferMemoryBarrier bar{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  bar.srcQueueFamilyIndex = bar.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  bar.buffer = a.buffer;
  bar.offset = 128;
  bar.size = 256;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 1, &bar, 0,
                       nullptr);
  expectVkrtMessage("VUID-VkBufferMemoryBarrier-size-01189");
  submitAndWait(cb);
  for (int i = 0; i < 256; ++i) ASSERT_EQ(static_cast<uint8_t*>(a.data)[i], 0xaa) << i;
  for (int i = 0; i < 256; ++i) ASSERT_EQ(static_cast<uint8_t*>(b.data)[i], 0xbb) << i;
  destroy(a);
  destroy(b);
  destroy(noSrc);
}

TEST_F(CommandsMisuseTest, PushConstantRulesAreReported) {
  // Compute owns [0, 64), ray generation [32, 128): bytes 32..63 belong to both.
  VkPushConstantRange ranges[2] = {{VK_SHADER_STAGE_COMPUTE_BIT, 0, 64}, {VK_SHADER_STAGE_RAYGEN_BIT_KHR, 32, 96}};
  VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  plci.pushConstantRangeCount = 2;
  plci.pPushConstantRanges = ranges;
  VkPipelineLayout layout;
  ASSERT_EQ(vkCreatePipelineLayout(device, &plci, nullptr, &layout), VK_SUCCESS);
  VkCommandBuffer cb = beginOneTime();
  uint32_t v[64] = {};
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 2, 4, v);
  expectVkrtMessage("VUID-vkCmdPushConstants-offset-00368");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 6, v);
  expectVkrtMessage("VUID-vkCmdPushConstants-size-00369");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 256, 4, v);
  expectVkrtMessage("VUID-vkCmdPushConstants-offset-00370");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 128, 132, v);
  expectVkrtMessage("VUID-vkCmdPushConstants-size-00371");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 128, 4, v);  // no range holds byte 128
  expectVkrtMessage("VUID-vkCmdPushConstants-offset-01795");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 32, 4, v);  // the raygen range overlaps too
  expectVkrtMessage("VUID-vkCmdPushConstants-offset-01796");
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 32, v);  // valid
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_RAYGEN_BIT_KHR, 32, 32, v);
  vkCmdPushConstants(cb, layout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 64, 64, v);
  EXPECT_TRUE(vkrtMessages().empty());
  submitAndWait(cb);
  vkDestroyPipelineLayout(device, layout, nullptr);
}

TEST_F(CommandsMisuseTest, UnbalancedDebugLabelsAreReported) {
  auto qEnd = reinterpret_cast<PFN_vkQueueEndDebugUtilsLabelEXT>(
      vkGetInstanceProcAddr(instance, "vkQueueEndDebugUtilsLabelEXT"));
  auto endLabel =
      reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(vkGetInstanceProcAddr(instance, "vkCmdEndDebugUtilsLabelEXT"));
  ASSERT_TRUE(qEnd && endLabel);
  qEnd(queue);
  expectVkrtMessage("VUID-vkQueueEndDebugUtilsLabelEXT-None-01911");
  VkCommandBuffer sec = allocate(VK_COMMAND_BUFFER_LEVEL_SECONDARY);
  ASSERT_EQ(begin(sec, 0, true), VK_SUCCESS);
  endLabel(sec);
  expectVkrtMessage("VUID-vkCmdEndDebugUtilsLabelEXT-commandBuffer-01913");
  ASSERT_EQ(vkEndCommandBuffer(sec), VK_SUCCESS);
  vkFreeCommandBuffers(device, commandPool, 1, &sec);
}

}  // namespace
}  // namespace vkrt::test
