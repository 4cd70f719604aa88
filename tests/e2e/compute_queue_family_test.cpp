// vkrt's second queue family, compute and transfer without graphics (what the CTS's compute groups look for: "No
// queue family found that only supports compute queue"): a device with queues of both families, dispatches and copies
// submitted to the compute-only queue, and the graphics commands refused in its command buffers with their
// "commandBuffer-cmdpool" VUIDs (and the graphics bind point, and occlusion queries), the valid use not reported.
#include <cstring>
#include <vector>

#include "compute_fill.comp.spv.h"
#include "e2e/compute_pipeline_helpers.hpp"
#include "e2e/fixture.hpp"

namespace vkrt::test {
namespace {

class ComputeQueueFamilyTest : public VulkanTest {
 protected:
  // The misuse below is vkrt's to report (the layer would report it too).
  FixtureOptions options() override {
    FixtureOptions o;
    o.validation = false;
    return o;
  }
  // A second device with one queue of each family (the fixture's has family 0 only); its objects are the test's.
  VkDevice dev = VK_NULL_HANDLE;
  VkQueue graphicsQueue = VK_NULL_HANDLE, computeQueue = VK_NULL_HANDLE;
  void SetUp() override {
    VulkanTest::SetUp();
    if (HasFatalFailure()) return;
    float prio = 1;
    VkDeviceQueueCreateInfo q[2] = {{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO},
                                    {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO}};
    for (uint32_t f = 0; f < 2; ++f) {
      q[f].queueFamilyIndex = f;
      q[f].queueCount = 1;
      q[f].pQueuePriorities = &prio;
    }
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
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

}  // namespace
}  // namespace vkrt::test
