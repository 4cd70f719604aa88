// Robustness of shader execution (docs/device-loss.md): a shader that never ends is stopped by vkrt's watchdog after
// VKRT_SHADER_TIMEOUT_MS, a shader that stores through a wild device address faults; either loses the device (the
// specification's "Lost Device"): one report names the pipeline, the shader and an invocation, the fence and semaphore
// waits return VK_ERROR_DEVICE_LOST, later submissions are refused, and everything can still be destroyed.
//
// The time limit and the fault recovery are vkrt's: other drivers have their own timeouts (seconds) and treat
// faults their own way, so the tests run on vkrt only. The limit is set to kTimeoutMs before each device is made.
#include <chrono>
#include <cinttypes>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"
#include "e2e/trace_fixture.hpp"
#include "watchdog.rgen.spv.h"
#include "watchdog.rmiss.spv.h"
#include "watchdog_fault.comp.spv.h"
#include "watchdog_fault_barrier.comp.spv.h"
#include "watchdog_spin.comp.spv.h"
#include "watchdog_spin_barrier.comp.spv.h"

namespace vkrt::test {
namespace {

constexpr const char* kTimeoutMs = "300";
// Nothing is mapped at this address (it lies below the lowest address Linux lets a process map).
constexpr VkDeviceAddress kWildAddress = 0x1000;

// The validation layer does not follow a device loss: a submission's command buffer, fence and semaphores stay
// "in use" for it after the waits returned VK_ERROR_DEVICE_LOST, so it reports their destruction. Those reports,
// and only those, are accepted after a loss.
const char* const kInUseAfterLoss[] = {"VUID-vkFreeCommandBuffers-pCommandBuffers-00047",
                                       "VUID-vkDestroyFence-fence-01120", "VUID-vkDestroySemaphore-semaphore-01137"};

// VKRT_SPMD=0 (tools/test.sh runs the barrier tests so too): compute shaders on the scalar path, a workgroup with
// barriers as one fiber per invocation.
bool scalarPath() {
  const char* spmd = std::getenv("VKRT_SPMD");
  return spmd && std::string(spmd) == "0";
}

std::string hex(uint64_t v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%" PRIx64, v);
  return buf;
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Checks the one vkrt report of the loss for each of `parts`, then clears it.
template <class Test>
void acceptInUseAfterLoss(Test& t) {
  EXPECT_TRUE(t.vkrtMessagesForTest().empty());
  for (const Message& m : t.layerMessagesForTest()) {
    bool known = false;
    for (const char* v : kInUseAfterLoss) known |= m.idName == v;
    EXPECT_TRUE(known) << "validation layer: " << m.text;
  }
  t.clearMessagesForTest();
}

// Names `object` (a pipeline) for the loss report.
void name(VkDevice device, uint64_t object, const char* text) {
  auto setName =
      reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(vkGetDeviceProcAddr(device, "vkSetDebugUtilsObjectNameEXT"));
  VkDebugUtilsObjectNameInfoEXT ni{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  ni.objectType = VK_OBJECT_TYPE_PIPELINE;
  ni.objectHandle = object;
  ni.pObjectName = text;
  ASSERT_EQ(setName(device, &ni), VK_SUCCESS);
}

template <class Test>
void expectLossReport(Test& t, const std::vector<std::string>& parts) {
  std::vector<Message> m = t.vkrtMessagesForTest();
  ASSERT_EQ(m.size(), 1u) << (m.empty() ? std::string("no report") : m[0].text + " ... " + m.back().text);
  for (const std::string& p : parts) EXPECT_NE(m[0].text.find(p), std::string::npos) << p << " in: " << m[0].text;
  t.clearMessagesForTest();
}

class ShaderWatchdogTest : public VulkanTest {
 public:
  std::vector<Message> vkrtMessagesForTest() { return vkrtMessages(); }
  std::vector<Message> layerMessagesForTest() { return layerMessages(); }
  void clearMessagesForTest() { clearMessages(); }

 protected:
  void SetUp() override {
    setenv("VKRT_SHADER_TIMEOUT_MS", kTimeoutMs, 1);
    VulkanTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's watchdog and fault recovery; other drivers have their own";
  }
  void TearDown() override {
    VulkanTest::TearDown();
    unsetenv("VKRT_SHADER_TIMEOUT_MS");
  }

  VkFence fence() {
    VkFenceCreateInfo ci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateFence(device, &ci, nullptr, &f), VK_SUCCESS);
    return f;
  }
  VkSemaphore timeline() {
    VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo ci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &tci};
    VkSemaphore s = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateSemaphore(device, &ci, nullptr, &s), VK_SUCCESS);
    return s;
  }
  VkDeviceAddress addressOf(const HostBuffer& b) {
    VkBufferDeviceAddressInfo i{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
    i.buffer = b.buffer;
    return vkGetBufferDeviceAddress(device, &i);
  }
  void submit(VkCommandBuffer cb, VkFence f, VkSemaphore signal = VK_NULL_HANDLE, uint64_t value = 0) {
    VkTimelineSemaphoreSubmitInfo tl{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    tl.signalSemaphoreValueCount = 1;
    tl.pSignalSemaphoreValues = &value;
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, signal ? &tl : nullptr};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    si.signalSemaphoreCount = signal ? 1 : 0;
    si.pSignalSemaphores = &signal;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, f), VK_SUCCESS);
  }

  // A dispatch of `groups` workgroups of the spinning shader (watchdog_spin*.comp) with `spinner` looping.
  VkCommandBuffer spinDispatch(ComputePipeline& p, HostBuffer& data, uint32_t groups, uint32_t spinner) {
    VkDescriptorBufferInfo bi{data.buffer, 0, VK_WHOLE_SIZE};
    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    w.dstSet = p.set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &bi;
    vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &spinner);
    vkCmdDispatch(cb, groups, 1, 1);
    EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    return cb;
  }

  // What stays valid after the loss: the submission's fence reports the loss, submits and waits return it.
  void expectLostDevice(VkFence f) {
    if (f) {
      EXPECT_EQ(vkGetFenceStatus(device, f), VK_ERROR_DEVICE_LOST);
    }
    EXPECT_EQ(vkQueueWaitIdle(queue), VK_ERROR_DEVICE_LOST);
    EXPECT_EQ(vkDeviceWaitIdle(device), VK_ERROR_DEVICE_LOST);
    VkCommandBuffer empty = beginOneTime();
    EXPECT_EQ(vkEndCommandBuffer(empty), VK_SUCCESS);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &empty;
    EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_ERROR_DEVICE_LOST);
    vkFreeCommandBuffers(device, commandPool, 1, &empty);
  }
};

// A workgroup whose invocation 70 loops forever: the fence wait returns VK_ERROR_DEVICE_LOST after about the time
// limit; the report names the pipeline, the shader and the workgroup (shaders without barriers run a workgroup in
// one call); then everything is destroyed.
TEST_F(ShaderWatchdogTest, ARunawayComputeShaderLosesTheDeviceAfterTheTimeLimit) {
  constexpr uint32_t kGroups = 4, kSpinner = 70;
  HostBuffer data = createHostBuffer(4 * (1 + 64 * kGroups), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(data.data, 0, data.size);
  ComputePipeline p = makeComputePipeline(device, kSpv_watchdog_spin_comp, sizeof kSpv_watchdog_spin_comp,
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
  ASSERT_EQ(p.result, VK_SUCCESS);
  name(device, uint64_t(p.pipeline), "runaway");
  VkCommandBuffer cb = spinDispatch(p, data, kGroups, kSpinner);
  VkFence f = fence();
  submit(cb, f);
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX), VK_ERROR_DEVICE_LOST);
  const double waited = secondsSince(t0);
  EXPECT_GE(waited, 0.25);
  EXPECT_LT(waited, 30.0);
  expectLossReport(*this, {"device lost (VK_ERROR_DEVICE_LOST)", "compute shader \"main\"", "VkPipeline 0x",
                           "'runaway'", "of pipeline 0x", "300 ms", "VKRT_SHADER_TIMEOUT_MS", "WorkgroupId (1, 0, 0)"});
  expectLostDevice(f);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  vkDestroyFence(device, f, nullptr);
  destroyComputePipeline(device, p);
  destroy(data);
  acceptInUseAfterLoss(*this);
}

// The same with a workgroup barrier (the workgroup's batches run as fibers; with VKRT_SPMD=0 its invocations, one
// fiber each): the report names the workgroup (the batch's lanes run together) or, on the scalar path, the
// invocation; a timeline semaphore the submission signals still reaches its value, and a host wait for a value nothing
// will signal returns instead of waiting forever; both report the loss.
TEST_F(ShaderWatchdogTest, ARunawayShaderWithBarriersNamesItsInvocationAndSemaphoreWaitsReturn) {
  constexpr uint32_t kGroups = 2, kSpinner = 70;
  HostBuffer data = createHostBuffer(4 * (1 + 64 * kGroups), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memset(data.data, 0, data.size);
  ComputePipeline p =
      makeComputePipeline(device, kSpv_watchdog_spin_barrier_comp, sizeof kSpv_watchdog_spin_barrier_comp,
                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 4);
  ASSERT_EQ(p.result, VK_SUCCESS);
  name(device, uint64_t(p.pipeline), "runaway");
  VkCommandBuffer cb = spinDispatch(p, data, kGroups, kSpinner);
  VkSemaphore sem = timeline();
  submit(cb, VK_NULL_HANDLE, sem, 1);
  uint64_t one = 1, two = 2;
  VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wi.semaphoreCount = 1;
  wi.pSemaphores = &sem;
  wi.pValues = &one;
  EXPECT_EQ(vkWaitSemaphores(device, &wi, UINT64_MAX), VK_ERROR_DEVICE_LOST);
  uint64_t value = 0;
  EXPECT_EQ(vkGetSemaphoreCounterValue(device, sem, &value), VK_ERROR_DEVICE_LOST);
  EXPECT_EQ(value, 1u) << "the batch's signal still happened";
  wi.pValues = &two;
  EXPECT_EQ(vkWaitSemaphores(device, &wi, UINT64_MAX), VK_ERROR_DEVICE_LOST);
  expectLossReport(*this, {"compute shader \"main\"", "VkPipeline 0x", "'runaway'", "of pipeline 0x",
                           scalarPath() ? "GlobalInvocationId (70, 0, 0)" : "WorkgroupId (1, 0, 0)"});
  expectLostDevice(VK_NULL_HANDLE);
  vkFreeCommandBuffers(device, commandPool, 1, &cb);
  vkDestroySemaphore(device, sem, nullptr);
  destroyComputePipeline(device, p);
  destroy(data);
  acceptInUseAfterLoss(*this);
}

// A store through a device address where nothing is mapped: the fault is caught, the device lost, the report names
// the shader, the address and the workgroup (the scalar path's fibers, with barriers and VKRT_SPMD=0: the
// invocation), and the application goes on.
class ShaderFaultTest : public ShaderWatchdogTest {
 protected:
  void run(const uint32_t* words, size_t bytes, const std::string& who) {
    constexpr uint32_t kGroups = 2, kFaulter = 5;
    HostBuffer good = createHostBuffer(4 * 64 * kGroups, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    std::memset(good.data, 0, good.size);
    ComputePipeline p = makeComputePipeline(device, words, bytes, {}, 20);
    ASSERT_EQ(p.result, VK_SUCCESS);
    name(device, uint64_t(p.pipeline), "runaway");
    struct {
      VkDeviceAddress good, wild;
      uint32_t faulter;
    } push{addressOf(good), kWildAddress, kFaulter};
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
    vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 20, &push);
    vkCmdDispatch(cb, kGroups, 1, 1);
    ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    VkFence f = fence();
    submit(cb, f);
    EXPECT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX), VK_ERROR_DEVICE_LOST);
    expectLossReport(*this, {"device lost (VK_ERROR_DEVICE_LOST)", "compute shader \"main\"", "VkPipeline 0x",
                             "'runaway'", "of pipeline 0x", "faulted (SIGSEGV)", "address " + hex(kWildAddress), who});
    expectLostDevice(f);
    vkFreeCommandBuffers(device, commandPool, 1, &cb);
    vkDestroyFence(device, f, nullptr);
    destroyComputePipeline(device, p);
    destroy(good);
    acceptInUseAfterLoss(*this);
  }
};

TEST_F(ShaderFaultTest, AStoreThroughAWildDeviceAddressLosesTheDevice) {
  run(kSpv_watchdog_fault_comp, sizeof kSpv_watchdog_fault_comp, "WorkgroupId (0, 0, 0)");
}

TEST_F(ShaderFaultTest, AFaultInAFiberOfAWorkgroupWithBarriersNamesTheInvocation) {
#if defined(__SANITIZE_THREAD__)
  // Under ThreadSanitizer on the development VM of 2026-11-25 the fault of a fiber is not recovered: the dispatch
  // makes no progress until the watchdog ends it. The driver of 48502b9, which passed this test in CI on an earlier
  // VM, does the same there, so it is the sanitizer's signal handling on that machine, not a change of vkrt's; the
  // AddressSanitizer and release builds run the test.
  GTEST_SKIP() << "a fault in a fiber under ThreadSanitizer (see the comment)";
#endif
  run(kSpv_watchdog_fault_barrier_comp, sizeof kSpv_watchdog_fault_barrier_comp,
      scalarPath() ? "GlobalInvocationId (5, 0, 0)" : "WorkgroupId (0, 0, 0)");
}

// Ray tracing: a raygen shader that loops, a miss shader that loops under traceRayEXT, a raygen shader that loops
// on rayQueryProceedEXT, a raygen shader that stores through a wild address. Each loses the device; the report
// names the shader that was running and its launch index.
class RayWatchdogTest : public TraceTest {
 public:
  std::vector<Message> vkrtMessagesForTest() { return vkrtMessages(); }
  std::vector<Message> layerMessagesForTest() { return layerMessages(); }
  void clearMessagesForTest() { clearMessages(); }

 protected:
  VkPhysicalDeviceRayQueryFeaturesKHR rqf{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};

  FixtureOptions options() override {
    FixtureOptions o = TraceTest::options();
    o.deviceExtensions.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
    rqf.rayQuery = VK_TRUE;
    rqf.pNext = asf.pNext;
    asf.pNext = &rqf;
    return o;
  }
  void SetUp() override {
    setenv("VKRT_SHADER_TIMEOUT_MS", kTimeoutMs, 1);
    TraceTest::SetUp();
    if (HasFatalFailure() || !device) return;
    if (!onVkrt()) GTEST_SKIP() << "vkrt's watchdog and fault recovery; other drivers have their own";
  }
  void TearDown() override {
    TraceTest::TearDown();
    unsetenv("VKRT_SHADER_TIMEOUT_MS");
  }

  // Launches 8 x 4 rays with launch index (3, 2) misbehaving as `mode` says (watchdog.rgen); expects the loss and
  // its report to name `parts`.
  void launch(uint32_t mode, const std::vector<std::string>& parts) {
    VkShaderModule rg = module(kSpv_watchdog_rgen, sizeof kSpv_watchdog_rgen);
    VkShaderModule ms = module(kSpv_watchdog_rmiss, sizeof kSpv_watchdog_rmiss);
    Desc d;
    d.layout = traceLayout;
    d.general(rg, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    d.general(ms, VK_SHADER_STAGE_MISS_BIT_KHR);
    VkPipeline p = make(d);
    ASSERT_NE(p, VK_NULL_HANDLE);
    name(device, uint64_t(p), "runaway");
    Sbt s = sbt(p, 2, {0}, {{1}}, {});
    VkAccelerationStructureKHR scene = basicScene();
    HostBuffer& out = buffer(4 * 32, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memset(out.data, 0, out.size);
    VkWriteDescriptorSetAccelerationStructureKHR asw{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
    asw.accelerationStructureCount = 1;
    asw.pAccelerationStructures = &scene;
    VkDescriptorSet set = sceneSet(pool, setLayout, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, &asw, out);
    struct {
      uint32_t mode, x, y, pad;
      VkDeviceAddress wild;
      uint32_t rest[2];
    } params{mode, 3, 2, 0, kWildAddress, {0, 0}};
    static_assert(sizeof params == sizeof(TraceParams));
    VkCommandBuffer cb = beginOneTime();
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, p);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, traceLayout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cb, traceLayout, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, sizeof params, &params);
    cmdTrace(cb, &s.raygen, &s.miss, &s.hit, &s.callable, 8, 4, 1);
    ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence f = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateFence(device, &fci, nullptr, &f), VK_SUCCESS);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, f), VK_SUCCESS);
    EXPECT_EQ(vkWaitForFences(device, 1, &f, VK_TRUE, UINT64_MAX), VK_ERROR_DEVICE_LOST);
    std::vector<std::string> all = {"device lost (VK_ERROR_DEVICE_LOST)", "VkPipeline 0x", "'runaway'",
                                    "of pipeline 0x", "LaunchIdKHR (3, 2, 0)"};
    all.insert(all.end(), parts.begin(), parts.end());
    expectLossReport(*this, all);
    EXPECT_EQ(vkGetFenceStatus(device, f), VK_ERROR_DEVICE_LOST);
    VkCommandBuffer empty = beginOneTime();
    EXPECT_EQ(vkEndCommandBuffer(empty), VK_SUCCESS);
    si.pCommandBuffers = &empty;
    EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_ERROR_DEVICE_LOST);
    EXPECT_EQ(vkDeviceWaitIdle(device), VK_ERROR_DEVICE_LOST);
    vkFreeCommandBuffers(device, commandPool, 1, &empty);
    vkFreeCommandBuffers(device, commandPool, 1, &cb);
    vkDestroyFence(device, f, nullptr);
    vkFreeDescriptorSets(device, pool, 1, &set);
    // (The fixture destroys the pipeline and the modules.)
    acceptInUseAfterLoss(*this);
  }
};

TEST_F(RayWatchdogTest, ARunawayRaygenShaderLosesTheDevice) { launch(0, {"raygen shader \"main\"", "300 ms"}); }

TEST_F(RayWatchdogTest, ARunawayMissShaderUnderTraceRayLosesTheDevice) {
  launch(1, {"miss shader \"main\"", "300 ms"});
}

TEST_F(RayWatchdogTest, ALoopOnRayQueryProceedLosesTheDevice) { launch(3, {"raygen shader \"main\"", "300 ms"}); }

TEST_F(RayWatchdogTest, AFaultInARaygenShaderLosesTheDevice) {
  launch(2, {"raygen shader \"main\"", "faulted (SIGSEGV)", "address " + hex(kWildAddress)});
}

}  // namespace
}  // namespace vkrt::test
