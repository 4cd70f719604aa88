// buffer_demo: fills, updates and copies buffers through a queue submission ordered by a timeline semaphore,
// using plain Vulkan through the loader, and prints the resulting bytes.
//
//   VK_DRIVER_FILES=<build>/vkrt_icd.json ./buffer_demo
//
// Exits 0 and prints "buffer_demo: OK" when every byte is as expected.
#include <vulkan/vulkan.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "example_vk.hpp"

namespace {

struct HostBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint8_t* bytes = nullptr;
};

HostBuffer makeBuffer(VkPhysicalDevice pd, VkDevice dev, VkDeviceSize size) {
  HostBuffer b;
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  CHECK(vkCreateBuffer(dev, &bci, nullptr, &b.buffer));
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, b.buffer, &req);
  VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = example::memoryType(
      pd, req.memoryTypeBits, {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT}, "a buffer");
  CHECK(vkAllocateMemory(dev, &mai, nullptr, &b.memory));
  CHECK(vkBindBufferMemory(dev, b.buffer, b.memory, 0));
  void* p = nullptr;
  CHECK(vkMapMemory(dev, b.memory, 0, VK_WHOLE_SIZE, 0, &p));
  b.bytes = static_cast<uint8_t*>(p);
  return b;
}

void printBytes(const char* name, const uint8_t* bytes, size_t n) {
  std::printf("%s:", name);
  for (size_t i = 0; i < n; ++i) std::printf("%s%02x", i % 16 == 0 ? "\n  " : " ", bytes[i]);
  std::printf("\n");
}

}  // namespace

int main() {
  example::gProgram = "buffer_demo";
  const VkInstance instance = example::createInstance("buffer_demo");
  const VkPhysicalDevice pd = example::pickPhysicalDevice(instance);
  const uint32_t family = example::queueFamily(pd, VK_QUEUE_COMPUTE_BIT);  // compute queues do transfers too
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  f12.timelineSemaphore = VK_TRUE;
  const VkDevice dev = example::createDevice(pd, family, &f12);
  VkQueue queue;
  vkGetDeviceQueue(dev, family, 0, &queue);

  constexpr VkDeviceSize kSize = 64;
  HostBuffer src = makeBuffer(pd, dev, kSize);
  HostBuffer dst = makeBuffer(pd, dev, kSize);
  std::memset(src.bytes, 0, kSize);
  std::memset(dst.bytes, 0, kSize);

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = family;
  VkCommandPool pool;
  CHECK(vkCreateCommandPool(dev, &pci, nullptr, &pool));
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  CHECK(vkAllocateCommandBuffers(dev, &ai, &cb));

  // src = fill 0xa5 everywhere, then 16 bytes 0..15 at offset 16; dst[0..32) = src[16..48), dst[32..64) = 0x3c.
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  CHECK(vkBeginCommandBuffer(cb, &bi));
  vkCmdFillBuffer(cb, src.buffer, 0, VK_WHOLE_SIZE, 0xa5a5a5a5u);
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
  uint8_t ramp[16];
  for (int i = 0; i < 16; ++i) ramp[i] = static_cast<uint8_t>(i);
  vkCmdUpdateBuffer(cb, src.buffer, 16, sizeof ramp, ramp);
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, 0,
                       nullptr);
  VkBufferCopy region{16, 0, 32};
  vkCmdCopyBuffer(cb, src.buffer, dst.buffer, 1, &region);
  vkCmdFillBuffer(cb, dst.buffer, 32, 32, 0x3c3c3c3cu);
  CHECK(vkEndCommandBuffer(cb));

  // The submission waits for timeline value 1 (signaled by the host below) and signals 2 when done.
  VkSemaphoreTypeCreateInfo tci{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
  tci.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &tci};
  VkSemaphore timeline;
  CHECK(vkCreateSemaphore(dev, &sci, nullptr, &timeline));
  uint64_t waitValue = 1, signalValue = 2;
  VkTimelineSemaphoreSubmitInfo tsi{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  tsi.waitSemaphoreValueCount = 1;
  tsi.pWaitSemaphoreValues = &waitValue;
  tsi.signalSemaphoreValueCount = 1;
  tsi.pSignalSemaphoreValues = &signalValue;
  VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO, &tsi};
  si.waitSemaphoreCount = 1;
  si.pWaitSemaphores = &timeline;
  si.pWaitDstStageMask = &stage;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cb;
  si.signalSemaphoreCount = 1;
  si.pSignalSemaphores = &timeline;
  CHECK(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE));
  VkSemaphoreSignalInfo sig{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
  sig.semaphore = timeline;
  sig.value = 1;
  CHECK(vkSignalSemaphore(dev, &sig));
  VkSemaphoreWaitInfo wi{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wi.semaphoreCount = 1;
  wi.pSemaphores = &timeline;
  wi.pValues = &signalValue;
  CHECK(vkWaitSemaphores(dev, &wi, 5'000'000'000ull));

  printBytes("src", src.bytes, kSize);
  printBytes("dst", dst.bytes, kSize);
  int mismatches = 0;
  for (size_t i = 0; i < kSize; ++i) {
    const uint8_t wantSrc = (i >= 16 && i < 32) ? uint8_t(i - 16) : 0xa5;
    const uint8_t wantDst = i < 16 ? uint8_t(i) : (i < 32 ? 0xa5 : 0x3c);
    if (src.bytes[i] != wantSrc || dst.bytes[i] != wantDst) {
      std::fprintf(stderr, "buffer_demo: byte %zu: src %02x (want %02x), dst %02x (want %02x)\n", i, src.bytes[i],
                   wantSrc, dst.bytes[i], wantDst);
      ++mismatches;
    }
  }

  vkDestroySemaphore(dev, timeline, nullptr);
  vkDestroyCommandPool(dev, pool, nullptr);
  for (HostBuffer* b : {&src, &dst}) {
    vkDestroyBuffer(dev, b->buffer, nullptr);
    vkFreeMemory(dev, b->memory, nullptr);
  }
  vkDestroyDevice(dev, nullptr);
  vkDestroyInstance(instance, nullptr);
  if (mismatches) {
    std::printf("buffer_demo: FAILED (%d bytes differ)\n", mismatches);
    return 1;
  }
  std::printf("buffer_demo: OK\n");
  return 0;
}
