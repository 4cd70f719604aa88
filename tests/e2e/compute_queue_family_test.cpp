// vkrt's second queue family, compute and transfer without graphics (what the CTS's compute groups look for: "No
// queue family found that only supports compute queue"): a device with queues of both families, dispatches and copies
// submitted to the compute-only queue, and the graphics commands refused in its command buffers with their
// "commandBuffer-cmdpool" VUIDs (and the graphics bind point, and occlusion queries), the valid use not reported;
// and the graphics pipeline stages refused in its barriers, events and timestamps (VUID-vkCmdPipelineBarrier-
// srcStageMask-06461 and kin), by vkrt and, with the same VUIDs, by the validation layer.
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "compute_fill.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

class ComputeQueueFamilyTest : public VulkanTest {
 protected:
  // The misuse below is vkrt's to report (the layer would report it too).
  virtual bool layered() { return false; }
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = layered();
    return o;
  }
  // A second device with one queue of each family (the fixture's has family 0 only); its objects are the test's.
  VkDevice dev = VK_NULL_HANDLE;
  VkQueue graphicsQueue = VK_NULL_HANDLE, computeQueue = VK_NULL_HANDLE;
  void SetUp() override {
    VulkanTest::SetUp();
    if (HasFatalFailure()) return;
    // (The validation layer checks queue family indices against the count the application was told.)
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &families, nullptr);
    ASSERT_EQ(families, 2u);
    float prio = 1;
    VkDeviceQueueCreateInfo q[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                    {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
    for (uint32_t f = 0; f < 2; ++f) {
      q[f].queueFamilyIndex = f;
      q[f].queueCount = 1;
      q[f].pQueuePriorities = &prio;
    }
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.synchronization2 = VK_TRUE;  // the *2 barrier, event and timestamp commands
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f13};
    dci.queueCreateInfoCount = 2;
    dci.pQueueCreateInfos = q;
    ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &dev), VK_SUCCESS);
    vkGetDeviceQueue(dev, 0, 0, &graphicsQueue);
    vkGetDeviceQueue(dev, 1, 0, &computeQueue);
    ASSERT_NE(computeQueue, VK_NULL_HANDLE);
    EXPECT_TRUE(vkrtMessages().empty());
  }
  void TearDown() override {
    if (dev) vkDestroyDevice(dev, nullptr);
    VulkanTest::TearDown();
  }
  VkCommandBuffer begin(VkCommandPool pool) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    EXPECT_EQ(vkAllocateCommandBuffers(dev, &ai, &cb), VK_SUCCESS);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    EXPECT_EQ(vkBeginCommandBuffer(cb, &bi), VK_SUCCESS);
    return cb;
  }
  VkCommandPool pool(uint32_t family) {
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.queueFamilyIndex = family;
    VkCommandPool p = VK_NULL_HANDLE;
    EXPECT_EQ(vkCreateCommandPool(dev, &pci, nullptr, &p), VK_SUCCESS);
    return p;
  }
  // A host-visible buffer of the second device.
  struct Buf {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* data = nullptr;
  };
  Buf buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buf b;
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = size;
    ci.usage = usage;
    EXPECT_EQ(vkCreateBuffer(dev, &ci, nullptr, &b.buffer), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(dev, b.buffer, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memoryTypeIndex(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
    EXPECT_EQ(vkAllocateMemory(dev, &mai, nullptr, &b.memory), VK_SUCCESS);
    EXPECT_EQ(vkBindBufferMemory(dev, b.buffer, b.memory, 0), VK_SUCCESS);
    EXPECT_EQ(vkMapMemory(dev, b.memory, 0, VK_WHOLE_SIZE, 0, &b.data), VK_SUCCESS);
    return b;
  }
  void destroy(Buf& b) {
    vkDestroyBuffer(dev, b.buffer, nullptr);
    vkFreeMemory(dev, b.memory, nullptr);
  }
  using VulkanTest::destroy;
};

TEST_F(ComputeQueueFamilyTest, TheComputeOnlyQueueRunsDispatchesAndCopies) {
  ComputePipeline p = makeComputePipeline(dev, kSpv_compute_fill_comp, sizeof kSpv_compute_fill_comp,
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 8);
  ASSERT_EQ(p.result, VK_SUCCESS);
  Buf out = buffer(256 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  Buf copy = buffer(256 * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  std::memset(copy.data, 0, 256 * 4);
  writeStorageBuffers<Buf>(dev, p, {&out});
  VkCommandPool cp = pool(1);
  VkCommandBuffer cb = begin(cp);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  const uint32_t push[2] = {3, 7};
  vkCmdPushConstants(cb, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 8, push);
  vkCmdDispatch(cb, 4, 1, 1);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr,
                       0, nullptr);
  VkBufferCopy region{0, 0, 256 * 4};
  vkCmdCopyBuffer(cb, out.buffer, copy.buffer, 1, &region);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  ASSERT_EQ(vkQueueSubmit(computeQueue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(computeQueue), VK_SUCCESS);
  const uint32_t* v = static_cast<const uint32_t*>(copy.data);
  for (uint32_t i = 0; i < 256; ++i) ASSERT_EQ(v[i], i * 3 + 7) << i;
  // The compute family's command buffer on the graphics family's queue: the family must match.
  EXPECT_NE(vkQueueSubmit(graphicsQueue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  expectVkrtMessage("VUID-vkQueueSubmit-pCommandBuffers-00074");
  vkDestroyCommandPool(dev, cp, nullptr);
  destroy(out);
  destroy(copy);
  destroyComputePipeline(dev, p);
}

TEST_F(ComputeQueueFamilyTest, GraphicsCommandsAreRefusedInTheComputeFamilysCommandBuffers) {
  ComputePipeline p = makeComputePipeline(dev, kSpv_compute_fill_comp, sizeof kSpv_compute_fill_comp,
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}, 8);
  ASSERT_EQ(p.result, VK_SUCCESS);
  VkCommandPool cp = pool(1), gp = pool(0);
  VkCommandBuffer cb = begin(cp), gcb = begin(gp);
  // Each graphics command: reported, nothing recorded.
  vkCmdDraw(cb, 3, 1, 0, 0);
  expectVkrtMessage("VUID-vkCmdDraw-commandBuffer-cmdpool");
  vkCmdDrawIndexedIndirect(cb, VK_NULL_HANDLE, 0, 1, 0);
  expectVkrtMessage("VUID-vkCmdDrawIndexedIndirect-commandBuffer-cmdpool");
  VkViewport vp{0, 0, 4, 4, 0, 1};
  vkCmdSetViewport(cb, 0, 1, &vp);
  expectVkrtMessage("VUID-vkCmdSetViewport-commandBuffer-cmdpool");
  vkCmdSetCullMode(cb, VK_CULL_MODE_NONE);
  expectVkrtMessage("VUID-vkCmdSetCullMode-commandBuffer-cmdpool");
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.layerCount = 1;
  vkCmdBeginRendering(cb, &ri);
  expectVkrtMessage("VUID-vkCmdBeginRendering-commandBuffer-cmdpool");
  vkCmdBlitImage(cb, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_GENERAL, 0, nullptr,
                 VK_FILTER_NEAREST);
  expectVkrtMessage("VUID-vkCmdBlitImage-commandBuffer-cmdpool");
  VkDeviceSize zero = 0;
  VkBuffer none = VK_NULL_HANDLE;
  vkCmdBindVertexBuffers(cb, 0, 1, &none, &zero);
  expectVkrtMessage("VUID-vkCmdBindVertexBuffers-commandBuffer-cmdpool");
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline);
  expectVkrtMessage("VUID-vkCmdBindPipeline-pipelineBindPoint-00778");
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout, 0, 1, &p.set, 0, nullptr);
  expectVkrtMessage("VUID-vkCmdBindDescriptorSets-pipelineBindPoint-00361");
  VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  qi.queryType = VK_QUERY_TYPE_OCCLUSION;
  qi.queryCount = 1;
  VkQueryPool qp;
  ASSERT_EQ(vkCreateQueryPool(dev, &qi, nullptr, &qp), VK_SUCCESS);
  vkCmdResetQueryPool(cb, qp, 0, 1);
  EXPECT_TRUE(vkrtMessages().empty());
  vkCmdBeginQuery(cb, qp, 0, 0);
  expectVkrtMessage("VUID-vkCmdBeginQuery-queryType-00803");
  // Not graphics: events, compute binds, dispatches, transfers (and the same commands on the graphics family).
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &p.set, 0, nullptr);
  vkCmdSetViewport(gcb, 0, 1, &vp);
  vkCmdBindPipeline(gcb, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  vkCmdBeginQuery(gcb, qp, 0, 0);
  vkCmdEndQuery(gcb, qp, 0);
  EXPECT_TRUE(vkrtMessages().empty());
  EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  EXPECT_EQ(vkEndCommandBuffer(gcb), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyQueryPool(dev, qp, nullptr);
  vkDestroyCommandPool(dev, cp, nullptr);
  vkDestroyCommandPool(dev, gp, nullptr);
  destroyComputePipeline(dev, p);
}

TEST_F(ComputeQueueFamilyTest, QueueFamilyIndicesAreChecked) {
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = 2;
  VkCommandPool p = VK_NULL_HANDLE;
  EXPECT_NE(vkCreateCommandPool(dev, &pci, nullptr, &p), VK_SUCCESS);
  expectVkrtMessage("VUID-vkCreateCommandPool-queueFamilyIndex-01937");
  float prio[2] = {1, 1};
  VkDeviceQueueCreateInfo q[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                  {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
  for (auto& e : q) {
    e.queueFamilyIndex = 1;
    e.queueCount = 1;
    e.pQueuePriorities = prio;
  }
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 2;
  dci.pQueueCreateInfos = q;
  VkDevice d = VK_NULL_HANDLE;
  EXPECT_NE(vkCreateDevice(physicalDevice, &dci, nullptr, &d), VK_SUCCESS);
  expectVkrtMessage("VUID-VkDeviceCreateInfo-queueFamilyIndex-02802");
  q[1].queueFamilyIndex = 2;
  EXPECT_NE(vkCreateDevice(physicalDevice, &dci, nullptr, &d), VK_SUCCESS);
  expectVkrtMessage("VUID-VkDeviceQueueCreateInfo-queueFamilyIndex-00381");
  // Both families, the valid use: no report.
  q[1].queueFamilyIndex = 0;
  q[1].queueCount = 2;
  ASSERT_EQ(vkCreateDevice(physicalDevice, &dci, nullptr, &d), VK_SUCCESS);
  EXPECT_TRUE(vkrtMessages().empty());
  VkQueue q1 = VK_NULL_HANDLE, q0 = VK_NULL_HANDLE;
  vkGetDeviceQueue(d, 1, 0, &q1);
  vkGetDeviceQueue(d, 0, 1, &q0);
  EXPECT_NE(q1, VK_NULL_HANDLE);
  EXPECT_NE(q0, VK_NULL_HANDLE);
  vkDestroyDevice(d, nullptr);
}

// ---- pipeline stages a compute-only family does not support ("Supported pipeline stage flags": the graphics stages
// need VK_QUEUE_GRAPHICS_BIT)

// Each command that names pipeline stages, recorded with one stage mask, and the VUID of a mask the command buffer's
// family does not support.
struct StageCommand {
  const char* name;
  const char* vuid;
  bool sync2;  // takes VkPipelineStageFlags2 (the stages beyond bit 31 apply)
  std::function<void(VkCommandBuffer, VkPipelineStageFlags2)> record;
  // What the validation layer of vk.xml 1.3.239 reports instead (null: it does not check the rule); by default the
  // same VUID.
  const char* layerId = "";
};
// The layer's lapses: vkCmdSetEvent2's stage rules under an UNASSIGNED id, vkCmdWriteTimestamp's not checked.
constexpr const char* kLayerUnassigned = "UNASSIGNED-CoreChecks-unhandled-queue-capabilities";

// The stages whose required queue capability is VK_QUEUE_GRAPHICS_BIT (but geometry and tessellation, whose features
// vkrt lacks: they are reported for that first), and stages every family with compute or transfer supports.
constexpr VkPipelineStageFlags2 kGraphicsStages[] = {
    VK_PIPELINE_STAGE_2_VERTEX_INPUT_BIT,           VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT,
    VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
    VK_PIPELINE_STAGE_2_ALL_GRAPHICS_BIT,           VK_PIPELINE_STAGE_2_INDEX_INPUT_BIT,
    VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT, VK_PIPELINE_STAGE_2_PRE_RASTERIZATION_SHADERS_BIT,
};
constexpr VkPipelineStageFlags2 kComputeStages[] = {
    VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT,   VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT,
    VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
    VK_PIPELINE_STAGE_2_TRANSFER_BIT,      VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
    VK_PIPELINE_STAGE_2_COPY_BIT,          VK_PIPELINE_STAGE_2_CLEAR_BIT,
    VK_PIPELINE_STAGE_2_RESOLVE_BIT,  // the table allows resolve and blit on compute and transfer queues
    VK_PIPELINE_STAGE_2_BLIT_BIT,          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_TRANSFER_BIT,
};

class QueueFamilyStagesTest : public ComputeQueueFamilyTest {
 protected:
  void SetUp() override {
    ComputeQueueFamilyTest::SetUp();
    if (HasFatalFailure()) return;
    VkEventCreateInfo ei{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
    ASSERT_EQ(vkCreateEvent(dev, &ei, nullptr, &event), VK_SUCCESS);
    VkQueryPoolCreateInfo qi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qi.queryCount = 2;
    ASSERT_EQ(vkCreateQueryPool(dev, &qi, nullptr, &timestamps), VK_SUCCESS);
  }
  void TearDown() override {
    if (dev) {
      vkDeviceWaitIdle(dev);
      vkDestroyEvent(dev, event, nullptr);
      vkDestroyQueryPool(dev, timestamps, nullptr);
    }
    ComputeQueueFamilyTest::TearDown();
  }
  static VkDependencyInfo dependency(const VkMemoryBarrier2* b) {
    VkDependencyInfo d{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    d.memoryBarrierCount = 1;
    d.pMemoryBarriers = b;
    return d;
  }
  // The commands; `src` says whether the mask is a barrier's source (else its destination).
  std::vector<StageCommand> commands() {
    const VkPipelineStageFlags kCompute = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    auto barrier2 = [](VkPipelineStageFlags2 src, VkPipelineStageFlags2 dst) {
      VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
      b.srcStageMask = src;
      b.dstStageMask = dst;
      return b;
    };
    return {
        {"vkCmdPipelineBarrier src", "VUID-vkCmdPipelineBarrier-srcStageMask-06461", false,
         [](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           vkCmdPipelineBarrier(cb, VkPipelineStageFlags(s), kCompute, 0, 0, nullptr, 0, nullptr, 0, nullptr);
         }},
        {"vkCmdPipelineBarrier dst", "VUID-vkCmdPipelineBarrier-dstStageMask-06462", false,
         [](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           vkCmdPipelineBarrier(cb, kCompute, VkPipelineStageFlags(s), 0, 0, nullptr, 0, nullptr, 0, nullptr);
         }},
        {"vkCmdPipelineBarrier2 src", "VUID-vkCmdPipelineBarrier2-srcStageMask-03849", true,
         [=](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(s, kCompute);
           VkDependencyInfo d = dependency(&b);
           vkCmdPipelineBarrier2(cb, &d);
         }},
        {"vkCmdPipelineBarrier2 dst", "VUID-vkCmdPipelineBarrier2-dstStageMask-03850", true,
         [=](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(kCompute, s);
           VkDependencyInfo d = dependency(&b);
           vkCmdPipelineBarrier2(cb, &d);
         }},
        {"vkCmdSetEvent", "VUID-vkCmdSetEvent-stageMask-06457", false,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) { vkCmdSetEvent(cb, event, VkPipelineStageFlags(s)); }},
        {"vkCmdResetEvent", "VUID-vkCmdResetEvent-stageMask-06458", false,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) { vkCmdResetEvent(cb, event, VkPipelineStageFlags(s)); }},
        {"vkCmdSetEvent2 src", "VUID-vkCmdSetEvent2-srcStageMask-03827", true,
         [=, this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(s, kCompute);
           VkDependencyInfo d = dependency(&b);
           vkCmdSetEvent2(cb, event, &d);
         },
         kLayerUnassigned},
        {"vkCmdSetEvent2 dst", "VUID-vkCmdSetEvent2-dstStageMask-03828", true,
         [=, this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(kCompute, s);
           VkDependencyInfo d = dependency(&b);
           vkCmdSetEvent2(cb, event, &d);
         },
         kLayerUnassigned},
        {"vkCmdWaitEvents src", "VUID-vkCmdWaitEvents-srcStageMask-06459", false,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           vkCmdWaitEvents(cb, 1, &event, VkPipelineStageFlags(s), kCompute, 0, nullptr, 0, nullptr, 0, nullptr);
         }},
        {"vkCmdWaitEvents dst", "VUID-vkCmdWaitEvents-dstStageMask-06460", false,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           vkCmdWaitEvents(cb, 1, &event, kCompute, VkPipelineStageFlags(s), 0, nullptr, 0, nullptr, 0, nullptr);
         }},
        {"vkCmdWaitEvents2 src", "VUID-vkCmdWaitEvents2-srcStageMask-03842", true,
         [=, this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(s, kCompute);
           VkDependencyInfo d = dependency(&b);
           vkCmdWaitEvents2(cb, 1, &event, &d);
         }},
        {"vkCmdWaitEvents2 dst", "VUID-vkCmdWaitEvents2-dstStageMask-03843", true,
         [=, this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           VkMemoryBarrier2 b = barrier2(kCompute, s);
           VkDependencyInfo d = dependency(&b);
           vkCmdWaitEvents2(cb, 1, &event, &d);
         }},
        {"vkCmdWriteTimestamp", "VUID-vkCmdWriteTimestamp-pipelineStage-04074", false,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) {
           vkCmdWriteTimestamp(cb, VkPipelineStageFlagBits(s), timestamps, 0);
         },
         nullptr},
        {"vkCmdWriteTimestamp2", "VUID-vkCmdWriteTimestamp2-stage-03860", true,
         [this](VkCommandBuffer cb, VkPipelineStageFlags2 s) { vkCmdWriteTimestamp2(cb, s, timestamps, 0); }},
    };
  }
  // Records every command with every stage of the lists into a command buffer of each family (one command buffer
  // per recording); `reports(c)` takes the reports of command c made since the last call and returns how many vkrt
  // made.
  void recordAll(const std::function<size_t(const StageCommand&)>& reports) {
    VkCommandPool pools[2] = {pool(0), pool(1)};
    for (const StageCommand& c : commands()) {
      auto each = [&](VkPipelineStageFlags2 stage, uint32_t family, bool reported) {
        const bool single = (stage & (stage - 1)) == 0;
        const bool timestamp = std::string(c.name).rfind("vkCmdWriteTimestamp", 0) == 0;
        if ((!c.sync2 && stage > 0x7fffffffu) || (timestamp && !single)) return;
        char trace[96];
        std::snprintf(trace, sizeof trace, "%s, stage 0x%llx, family %u", c.name, (unsigned long long)stage, family);
        SCOPED_TRACE(trace);
        VkCommandBuffer cb = begin(pools[family]);
        if (timestamp) vkCmdResetQueryPool(cb, timestamps, 0, 2);
        c.record(cb, stage);
        EXPECT_EQ(reports(c), reported ? 1u : 0u);
        EXPECT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
      };
      for (VkPipelineStageFlags2 s : kGraphicsStages) {
        each(s, 1, true);
        each(s, 0, false);
      }
      for (VkPipelineStageFlags2 s : kComputeStages) {
        each(s, 1, false);
        each(s, 0, false);
      }
    }
    vkDestroyCommandPool(dev, pools[0], nullptr);
    vkDestroyCommandPool(dev, pools[1], nullptr);
  }

  VkEvent event = VK_NULL_HANDLE;
  VkQueryPool timestamps = VK_NULL_HANDLE;
};

TEST_F(QueueFamilyStagesTest, GraphicsStagesAreReportedOnTheComputeFamilyOnly) {
  recordAll([&](const StageCommand& c) {
    const std::string vuid = c.vuid;
    std::vector<Message> m = vkrtMessages();
    clearMessages();
    size_t n = 0;
    for (const Message& x : m) {
      EXPECT_EQ(x.idName, vuid) << x.text;
      n += x.idName == vuid && x.text.find("queue family 1") != std::string::npos;
    }
    return n;
  });
}

// The refused command records nothing: the event stays reset, the timestamp unwritten; the same commands with the
// compute stage take effect.
TEST_F(QueueFamilyStagesTest, ARefusedEventOrTimestampHasNoEffect) {
  VkCommandPool cp = pool(1);
  VkCommandBuffer cb = begin(cp);
  vkCmdResetQueryPool(cb, timestamps, 0, 2);
  vkCmdSetEvent(cb, event, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT);
  expectVkrtMessage("VUID-vkCmdSetEvent-stageMask-06457");
  vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, timestamps, 0);
  expectVkrtMessage("VUID-vkCmdWriteTimestamp-pipelineStage-04074");
  vkCmdWriteTimestamp2(cb, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, timestamps, 1);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  ASSERT_EQ(vkQueueSubmit(computeQueue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(computeQueue), VK_SUCCESS);
  EXPECT_EQ(vkGetEventStatus(dev, event), VK_EVENT_RESET);
  uint64_t t = 0;
  EXPECT_EQ(vkGetQueryPoolResults(dev, timestamps, 0, 1, 8, &t, 8, VK_QUERY_RESULT_64_BIT), VK_NOT_READY);
  EXPECT_EQ(vkGetQueryPoolResults(dev, timestamps, 1, 1, 8, &t, 8, VK_QUERY_RESULT_64_BIT), VK_SUCCESS);
  // The valid one, on the same family: the event is set.
  cb = begin(cp);
  vkCmdSetEvent(cb, event, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT);
  ASSERT_EQ(vkEndCommandBuffer(cb), VK_SUCCESS);
  ASSERT_EQ(vkQueueSubmit(computeQueue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  ASSERT_EQ(vkQueueWaitIdle(computeQueue), VK_SUCCESS);
  EXPECT_EQ(vkGetEventStatus(dev, event), VK_EVENT_SET);
  EXPECT_TRUE(vkrtMessages().empty());
  vkDestroyCommandPool(dev, cp, nullptr);
}

// The validation layer draws the same line with the same VUIDs (and passes the call on: the fixture's callback
// returns VK_FALSE, so vkrt reports it too).
class QueueFamilyStagesLayerTest : public QueueFamilyStagesTest {
 protected:
  bool layered() override { return true; }
};

TEST_F(QueueFamilyStagesLayerTest, TheLayerReportsTheSameStagesWithTheSameVuids) {
  recordAll([&](const StageCommand& c) {
    const std::string vuid = c.vuid;
    size_t ours = 0;
    for (const Message& m : vkrtMessages()) {
      EXPECT_EQ(m.idName, vuid) << m.text;
      ours += m.idName == vuid;
    }
    if (c.layerId) {
      EXPECT_EQ(takeLayerMessages(*c.layerId ? c.layerId : c.vuid), ours) << "vkrt and the layer disagree";
    }
    for (const Message& m : layerMessages()) ADD_FAILURE() << "validation layer: " << m.text;
    clearMessages();
    return ours;
  });
}

}  // namespace
}  // namespace vkrt::test
