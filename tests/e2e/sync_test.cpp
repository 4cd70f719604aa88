// Fences, binary and timeline semaphores (host and queue operations, wait-before-signal across threads and
// queues), events, queue idling, vkQueueSubmit2, and misuse reported by VUID.
#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

using Clock = std::chrono::steady_clock;
constexpr VkBufferUsageFlags kXfer = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

class SyncTest : public VulkanTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o;
    o.queueCount = 2;
    return o;
  }
  void SetUp() override {
    VulkanTest::SetUp();
    if (device) vkGetDeviceQueue(device, 0, 1, &queue1);
  }
  VkFence fence(bool signaled) {
    VkFenceCreateInfo ci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    ci.flags = signaled ? VK_FENCE_CREATE_SIGNALED_BIT : 0;
    VkFence f = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFence(device, &ci, nullptr, &f), VK_SUCCESS);
    return f;
  }
  VkSemaphore semaphore(bool timeline, uint64_t initial = 0) {
    VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    tci.initialValue = initial;
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, timeline ? &tci : nullptr};
    VkSemaphore s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(device, &ci, nullptr, &s), VK_SUCCESS);
    return s;
  }
  VkEvent event(VkEventCreateFlags flags = 0) {
    VkEventCreateInfo ci{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
    ci.flags = flags;
    VkEvent e = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateEvent(device, &ci, nullptr, &e), VK_SUCCESS);
    return e;
  }
  // A recorded (ended) primary command buffer filling `buf` with `value`.
  VkCommandBuffer fillCommands(VkBuffer buf, uint32_t value) {
    VkCommandBuffer cb = beginOneTime();
    vkCmdFillBuffer(cb, buf, 0, VK_WHOLE_SIZE, value);
    EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    return cb;
  }
  VkCommandBuffer copyCommands(VkBuffer src, VkBuffer dst, VkDeviceSize size) {
    VkCommandBuffer cb = beginOneTime();
    VkBufferCopy r{0, 0, size};
    vkCmdCopyBuffer(cb, src, dst, 1, &r);
    EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    return cb;
  }
  // Submits with one optional wait and one optional signal (timeline values are used for timeline semaphores).
  VkResult submit(VkQueue q, VkCommandBuffer cb, VkSemaphore wait, uint64_t waitValue, VkSemaphore signal,
                  uint64_t signalValue, VkFence f = VK_NULL_HANDLE) {
    VkTimelineSemaphoreSubmitInfo tsi{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    tsi.waitSemaphoreValueCount = wait ? 1 : 0;
    tsi.pWaitSemaphoreValues = &waitValue;
    tsi.signalSemaphoreValueCount = signal ? 1 : 0;
    tsi.pSignalSemaphoreValues = &signalValue;
    VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, &tsi};
    si.waitSemaphoreCount = wait ? 1 : 0;
    si.pWaitSemaphores = &wait;
    si.pWaitDstStageMask = &stage;
    si.commandBufferCount = cb ? 1 : 0;
    si.pCommandBuffers = &cb;
    si.signalSemaphoreCount = signal ? 1 : 0;
    si.pSignalSemaphores = &signal;
    return vkQueueSubmit(q, 1, &si, f);
  }
  uint64_t counter(VkSemaphore s) {
    uint64_t v = ~0ull;
    EXPECT_EQ(vkGetSemaphoreCounterValue(device, s, &v), VK_SUCCESS);
    return v;
  }
  VkResult waitValue(VkSemaphore s, uint64_t value, uint64_t timeout) {
    VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
    wi.semaphoreCount = 1;
    wi.pSemaphores = &s;
    wi.pValues = &value;
    return vkWaitSemaphores(device, &wi, timeout);
  }
  VkResult hostSignal(VkSemaphore s, uint64_t value) {
    VkSemaphoreSignalInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
    si.semaphore = s;
    si.value = value;
    return vkSignalSemaphore(device, &si);
  }
  static uint32_t word(const HostBuffer& b, size_t i) {
    uint32_t v;
    std::memcpy(&v, static_cast<const uint8_t*>(b.data) + 4 * i, 4);
    return v;
  }
  void freeCb(VkCommandBuffer cb) { vkFreeCommandBuffers(device, commandPool, 1, &cb); }

  VkQueue queue1 = VK_NULL_HANDLE;
};

TEST_F(SyncTest, FencesStartSignaledOrNotAndHonourTimeouts) {
  VkFence on = fence(true), off = fence(false);
  EXPECT_EQ(vkGetFenceStatus(device, on), VK_SUCCESS);
  EXPECT_EQ(vkGetFenceStatus(device, off), VK_NOT_READY);
  EXPECT_EQ(vkWaitForFences(device, 1, &on, VK_TRUE, 0), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(device, 1, &off, VK_TRUE, 0), VK_TIMEOUT);
  auto t0 = Clock::now();
  EXPECT_EQ(vkWaitForFences(device, 1, &off, VK_TRUE, 20'000'000), VK_TIMEOUT);  // 20 ms
  EXPECT_GE(Clock::now() - t0, std::chrono::milliseconds(20));
  VkFence both[2] = {on, off};
  EXPECT_EQ(vkWaitForFences(device, 2, both, VK_FALSE, 0), VK_SUCCESS);    // any
  EXPECT_EQ(vkWaitForFences(device, 2, both, VK_TRUE, 1000), VK_TIMEOUT);  // all
  ASSERT_EQ(vkResetFences(device, 1, &on), VK_SUCCESS);
  EXPECT_EQ(vkGetFenceStatus(device, on), VK_NOT_READY);

  // A submission signals its fence after its work; an empty submission signals after earlier work.
  HostBuffer buf = createHostBuffer(256, kXfer);
  std::memset(buf.data, 0, 256);
  VkCommandBuffer cb = fillCommands(buf.buffer, 0x5a5a5a5a);
  ASSERT_EQ(submit(queue, cb, VK_NULL_HANDLE, 0, VK_NULL_HANDLE, 0, off), VK_SUCCESS);
  ASSERT_EQ(vkQueueSubmit(queue, 0, nullptr, on), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(device, 2, both, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  EXPECT_EQ(word(buf, 63), 0x5a5a5a5au);
  freeCb(cb);
  vkDestroyFence(device, on, nullptr);
  vkDestroyFence(device, off, nullptr);
  destroy(buf);
}

TEST_F(SyncTest, TimelineHostSignalsWaitsAndCounter) {
  VkSemaphore s = semaphore(true, 5);
  EXPECT_EQ(counter(s), 5u);
  EXPECT_EQ(waitValue(s, 5, 0), VK_SUCCESS);
  EXPECT_EQ(waitValue(s, 6, 0), VK_TIMEOUT);
  auto t0 = Clock::now();
  EXPECT_EQ(waitValue(s, 6, 10'000'000), VK_TIMEOUT);
  EXPECT_GE(Clock::now() - t0, std::chrono::milliseconds(10));
  ASSERT_EQ(hostSignal(s, 9), VK_SUCCESS);
  EXPECT_EQ(counter(s), 9u);
  EXPECT_EQ(waitValue(s, 7, 0), VK_SUCCESS);

  VkSemaphore t = semaphore(true, 0);
  VkSemaphore both[2] = {s, t};
  uint64_t values[2] = {9, 1};
  VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wi.semaphoreCount = 2;
  wi.pSemaphores = both;
  wi.pValues = values;
  EXPECT_EQ(vkWaitSemaphores(device, &wi, 0), VK_TIMEOUT);  // all: t is 0
  wi.flags = VK_SEMAPHORE_WAIT_ANY_BIT;
  EXPECT_EQ(vkWaitSemaphores(device, &wi, 0), VK_SUCCESS);
  wi.flags = 0;
  // Another thread signals while this one waits forever.
  std::thread signaler([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    EXPECT_EQ(hostSignal(t, 3), VK_SUCCESS);
  });
  EXPECT_EQ(vkWaitSemaphores(device, &wi, UINT64_MAX), VK_SUCCESS);
  signaler.join();
  EXPECT_EQ(counter(t), 3u);
  vkDestroySemaphore(device, s, nullptr);
  vkDestroySemaphore(device, t, nullptr);
}

TEST_F(SyncTest, TimelineWaitBeforeSignalAcrossThreadsAndQueues) {
  HostBuffer a = createHostBuffer(256, kXfer);
  HostBuffer b = createHostBuffer(256, kXfer);
  std::memset(a.data, 0, 256);
  std::memset(b.data, 0, 256);
  VkSemaphore tl = semaphore(true);
  VkCommandBuffer copy = copyCommands(a.buffer, b.buffer, 256);
  VkCommandBuffer fill = fillCommands(a.buffer, 0x600df00d);
  VkFence done = fence(false);
  // Queue 0: wait for 1 (nothing signals it yet), copy a -> b, signal 2.
  ASSERT_EQ(submit(queue, copy, tl, 1, tl, 2, done), VK_SUCCESS);
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_EQ(vkGetFenceStatus(device, done), VK_NOT_READY);
  EXPECT_EQ(counter(tl), 0u);
  EXPECT_EQ(word(b, 0), 0u);
  // Another thread submits the signal of 1 on queue 1, after filling a.
  std::thread other([&] { EXPECT_EQ(submit(queue1, fill, VK_NULL_HANDLE, 0, tl, 1), VK_SUCCESS); });
  EXPECT_EQ(waitValue(tl, 2, UINT64_MAX), VK_SUCCESS);
  other.join();
  EXPECT_EQ(vkWaitForFences(device, 1, &done, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  for (size_t i = 0; i < 64; ++i) ASSERT_EQ(word(b, i), 0x600df00du) << i;
  EXPECT_EQ(counter(tl), 2u);
  ASSERT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
  freeCb(copy);
  freeCb(fill);
  vkDestroyFence(device, done, nullptr);
  vkDestroySemaphore(device, tl, nullptr);
  destroy(a);
  destroy(b);
}

TEST_F(SyncTest, BinarySemaphoreOrdersTwoQueues) {
  HostBuffer a = createHostBuffer(128, kXfer);
  HostBuffer b = createHostBuffer(128, kXfer);
  std::memset(a.data, 0, 128);
  std::memset(b.data, 0, 128);
  VkSemaphore bin = semaphore(false);
  VkCommandBuffer fill = fillCommands(a.buffer, 0x12345678);
  VkCommandBuffer copy = copyCommands(a.buffer, b.buffer, 128);
  VkFence done = fence(false);
  ASSERT_EQ(submit(queue, fill, VK_NULL_HANDLE, 0, bin, 0), VK_SUCCESS);
  ASSERT_EQ(submit(queue1, copy, bin, 0, VK_NULL_HANDLE, 0, done), VK_SUCCESS);
  ASSERT_EQ(vkWaitForFences(device, 1, &done, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  for (size_t i = 0; i < 32; ++i) ASSERT_EQ(word(b, i), 0x12345678u) << i;
  ASSERT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
  freeCb(fill);
  freeCb(copy);
  vkDestroyFence(device, done, nullptr);
  vkDestroySemaphore(device, bin, nullptr);
  destroy(a);
  destroy(b);
}

TEST_F(SyncTest, QueueSubmit2WithTimelineSemaphores) {
  HostBuffer a = createHostBuffer(64, kXfer);
  HostBuffer b = createHostBuffer(64, kXfer);
  std::memset(a.data, 0, 64);
  std::memset(b.data, 0, 64);
  VkSemaphore tl = semaphore(true);
  VkCommandBuffer fill = fillCommands(a.buffer, 77);
  VkCommandBuffer copy = copyCommands(a.buffer, b.buffer, 64);
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait.semaphore = tl;
  wait.value = 10;
  wait.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkSemaphoreSubmitInfo signal = wait;
  signal.value = 20;
  VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cbi.commandBuffer = copy;
  VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si.waitSemaphoreInfoCount = 1;
  si.pWaitSemaphoreInfos = &wait;
  si.commandBufferInfoCount = 1;
  si.pCommandBufferInfos = &cbi;
  si.signalSemaphoreInfoCount = 1;
  si.pSignalSemaphoreInfos = &signal;
  ASSERT_EQ(vkQueueSubmit2(queue1, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);  // waits for 10
  VkCommandBufferSubmitInfo fci{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  fci.commandBuffer = fill;
  VkSemaphoreSubmitInfo first = wait;  // signals 10
  VkSubmitInfo2 si0{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  si0.commandBufferInfoCount = 1;
  si0.pCommandBufferInfos = &fci;
  si0.signalSemaphoreInfoCount = 1;
  si0.pSignalSemaphoreInfos = &first;
  ASSERT_EQ(vkQueueSubmit2(queue, 1, &si0, VK_NULL_HANDLE), VK_SUCCESS);
  EXPECT_EQ(waitValue(tl, 20, UINT64_MAX), VK_SUCCESS);
  EXPECT_EQ(word(b, 15), 77u);
  ASSERT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
  freeCb(fill);
  freeCb(copy);
  vkDestroySemaphore(device, tl, nullptr);
  destroy(a);
  destroy(b);
}

TEST_F(SyncTest, EventsFromHostAndCommandsAndQueueWaitIdleReallyWaits) {
  VkEvent e = event();
  EXPECT_EQ(vkGetEventStatus(device, e), VK_EVENT_RESET);
  ASSERT_EQ(vkSetEvent(device, e), VK_SUCCESS);
  EXPECT_EQ(vkGetEventStatus(device, e), VK_EVENT_SET);
  ASSERT_EQ(vkResetEvent(device, e), VK_SUCCESS);
  EXPECT_EQ(vkGetEventStatus(device, e), VK_EVENT_RESET);

  // The queue blocks in vkCmdWaitEvents until the host sets the event.
  HostBuffer buf = createHostBuffer(64, kXfer);
  std::memset(buf.data, 0, 64);
  VkCommandBuffer cb = beginOneTime();
  vkCmdWaitEvents(cb, 1, &e, VK_PIPELINE_STAGE_HOST_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, nullptr, 0, nullptr, 0,
                  nullptr);
  vkCmdFillBuffer(cb, buf.buffer, 0, VK_WHOLE_SIZE, 42);
  vkCmdResetEvent(cb, e, VK_PIPELINE_STAGE_TRANSFER_BIT);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkFence done = fence(false);
  ASSERT_EQ(submit(queue, cb, VK_NULL_HANDLE, 0, VK_NULL_HANDLE, 0, done), VK_SUCCESS);
  std::atomic<bool> idle{false};
  std::thread waiter([&] {
    EXPECT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
    idle = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  EXPECT_FALSE(idle.load());
  EXPECT_EQ(vkGetFenceStatus(device, done), VK_NOT_READY);
  EXPECT_EQ(word(buf, 0), 0u);
  ASSERT_EQ(vkSetEvent(device, e), VK_SUCCESS);
  waiter.join();
  EXPECT_TRUE(idle.load());
  EXPECT_EQ(vkGetFenceStatus(device, done), VK_SUCCESS);
  EXPECT_EQ(word(buf, 15), 42u);
  EXPECT_EQ(vkGetEventStatus(device, e), VK_EVENT_RESET);  // reset by the command buffer
  freeCb(cb);

  // Set by one command (synchronization2), waited on by a later one.
  VkMemoryBarrier2 mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  mb.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
  mb.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  mb.dstStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
  mb.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.memoryBarrierCount = 1;
  dep.pMemoryBarriers = &mb;
  cb = beginOneTime();
  vkCmdFillBuffer(cb, buf.buffer, 0, 32, 1);
  vkCmdSetEvent2(cb, e, &dep);
  vkCmdWaitEvents2(cb, 1, &e, &dep);
  vkCmdFillBuffer(cb, buf.buffer, 32, 32, 2);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  ASSERT_EQ(vkResetFences(device, 1, &done), VK_SUCCESS);
  ASSERT_EQ(submit(queue, cb, VK_NULL_HANDLE, 0, VK_NULL_HANDLE, 0, done), VK_SUCCESS);
  ASSERT_EQ(vkWaitForFences(device, 1, &done, VK_TRUE, UINT64_MAX), VK_SUCCESS);
  EXPECT_EQ(vkGetEventStatus(device, e), VK_EVENT_SET);
  EXPECT_EQ(word(buf, 0), 1u);
  EXPECT_EQ(word(buf, 15), 2u);
  freeCb(cb);
  vkDestroyFence(device, done, nullptr);
  vkDestroyEvent(device, e, nullptr);
  destroy(buf);
}

class SyncMisuseTest : public SyncTest {
 protected:
  FixtureOptions options() override {
    FixtureOptions o = SyncTest::options();
    o.validation = false;
    return o;
  }
};

TEST_F(SyncMisuseTest, FenceSemaphoreAndEventRulesAreReported) {
  VkFence on = fence(true);
  EXPECT_EQ(vkQueueSubmit(queue, 0, nullptr, on), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-fence-00063");

  VkSemaphore tl = semaphore(true, 4);
  EXPECT_EQ(hostSignal(tl, 4), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSemaphoreSignalInfo-value-03258");
  EXPECT_EQ(counter(tl), 4u);
  VkSemaphore bin = semaphore(false);
  EXPECT_EQ(hostSignal(bin, 1), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSemaphoreSignalInfo-semaphore-03257");
  EXPECT_EQ(waitValue(bin, 1, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSemaphoreWaitInfo-pSemaphores-03256");
  // A binary wait with no signal submitted; a timeline signal that does not increase the value.
  EXPECT_EQ(submit(queue, VK_NULL_HANDLE, bin, 0, VK_NULL_HANDLE, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pWaitSemaphores-03238");
  EXPECT_EQ(submit(queue, VK_NULL_HANDLE, VK_NULL_HANDLE, 0, tl, 3), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-VkSubmitInfo-pSignalSemaphores-03242");
  // Signaling a binary semaphore twice without a wait in between.
  ASSERT_EQ(submit(queue, VK_NULL_HANDLE, VK_NULL_HANDLE, 0, bin, 0), VK_SUCCESS);
  EXPECT_EQ(submit(queue, VK_NULL_HANDLE, VK_NULL_HANDLE, 0, bin, 0), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-pSignalSemaphores-00067");
  ASSERT_EQ(submit(queue, VK_NULL_HANDLE, bin, 0, VK_NULL_HANDLE, 0), VK_SUCCESS);  // consumes the signal

  // A fence given to a blocked submission cannot be reset or resubmitted.
  VkFence off = fence(false);
  ASSERT_EQ(submit(queue, VK_NULL_HANDLE, tl, 5, VK_NULL_HANDLE, 0, off), VK_SUCCESS);
  EXPECT_EQ(vkResetFences(device, 1, &off), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkResetFences-pFences-01123");
  EXPECT_EQ(vkQueueSubmit(queue1, 0, nullptr, off), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkQueueSubmit-fence-00064");
  EXPECT_EQ(vkGetFenceStatus(device, off), VK_NOT_READY);
  ASSERT_EQ(hostSignal(tl, 5), VK_SUCCESS);
  EXPECT_EQ(vkWaitForFences(device, 1, &off, VK_TRUE, UINT64_MAX), VK_SUCCESS);

  VkEvent devOnly = event(VK_EVENT_CREATE_DEVICE_ONLY_BIT);
  EXPECT_EQ(vkSetEvent(device, devOnly), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkSetEvent-event-03941");
  EXPECT_EQ(vkGetEventStatus(device, devOnly), VK_ERROR_VALIDATION_FAILED_EXT);
  expectVkrtMessage("VUID-vkGetEventStatus-event-03940");
  VkCommandBuffer cb = beginOneTime();
  vkCmdSetEvent(cb, devOnly, VK_PIPELINE_STAGE_HOST_BIT);
  expectVkrtMessage("VUID-vkCmdSetEvent-stageMask-01149");
  submitAndWait(cb);

  ASSERT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
  vkDestroyEvent(device, devOnly, nullptr);
  vkDestroyFence(device, on, nullptr);
  vkDestroyFence(device, off, nullptr);
  vkDestroySemaphore(device, tl, nullptr);
  vkDestroySemaphore(device, bin, nullptr);
}

}  // namespace
}  // namespace vkrt::test
