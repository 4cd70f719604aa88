#include "runtime/command_pool.hpp"

#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

CommandPool::CommandPool(Device* dev, const VkCommandPoolCreateInfo& info, const VkAllocationCallbacks* a)
    : Object(kType, dev->instance, dev), flags(info.flags), queueFamilyIndex(info.queueFamilyIndex) {
  if (a) {
    allocator = *a;
    hasAllocator = true;
  }
}

void CommandPool::freeBuffer(CommandBuffer* cb) {
  buffers.erase(cb);
  destroyObject(cb, alloc());
}

bool CommandPool::anyPending(CommandBuffer** which) const {
  for (CommandBuffer* cb : buffers) {
    if (cb->currentState() == CommandBuffer::State::Pending) {
      *which = cb;
      return true;
    }
  }
  return false;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

CommandPool* livePool(VkDevice device, VkCommandPool h, const char* fn, const char* vuid) {
  return liveOrReport<CommandPool>(fromHandle<Device>(device), h, fn, vuid);
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateCommandPool(VkDevice device, const VkCommandPoolCreateInfo* pCreateInfo,
                                                      const VkAllocationCallbacks* pAllocator,
                                                      VkCommandPool* pCommandPool) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkCreateCommandPool-queueFamilyIndex-01937
  if (pCreateInfo->queueFamilyIndex >= PhysicalDevice::kQueueFamilyCount) {
    report(dev, Severity::Error, "VUID-vkCreateCommandPool-queueFamilyIndex-01937",
           "vkCreateCommandPool: queueFamilyIndex %u is not a queue family of the device (vkrt has families 0 and 1)",
           pCreateInfo->queueFamilyIndex);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkCommandPoolCreateInfo-flags-02860
  if (pCreateInfo->flags & VK_COMMAND_POOL_CREATE_PROTECTED_BIT) {
    report(dev, Severity::Error, "VUID-VkCommandPoolCreateInfo-flags-02860",
           "vkCreateCommandPool: VK_COMMAND_POOL_CREATE_PROTECTED_BIT needs the protectedMemory feature, which vkrt "
           "does not support");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  CommandPool* p =
      createObject<CommandPool>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo, pAllocator);
  if (!p) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pCommandPool = toHandle(p);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyCommandPool(VkDevice device, VkCommandPool commandPool,
                                                   const VkAllocationCallbacks* pAllocator) {
  if (!commandPool) return;
  CommandPool* p =
      livePool(device, commandPool, "vkDestroyCommandPool", "VUID-vkDestroyCommandPool-commandPool-parameter");
  if (!p) return;
  CommandBuffer* busy = nullptr;
  // VUID-vkDestroyCommandPool-commandPool-00041
  if (p->anyPending(&busy)) {
    report(busy, Severity::Error, "VUID-vkDestroyCommandPool-commandPool-00041",
           "vkDestroyCommandPool: a command buffer of the pool is still pending execution");
    return;
  }
  std::vector<CommandBuffer*> all(p->buffers.begin(), p->buffers.end());
  for (CommandBuffer* cb : all) p->freeBuffer(cb);
  destroyObject(p, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_ResetCommandPool(VkDevice device, VkCommandPool commandPool,
                                                     VkCommandPoolResetFlags flags) {
  CommandPool* p = livePool(device, commandPool, "vkResetCommandPool", "VUID-vkResetCommandPool-commandPool-parameter");
  if (!p) return VK_ERROR_VALIDATION_FAILED_EXT;
  CommandBuffer* busy = nullptr;
  // VUID-vkResetCommandPool-commandPool-00040
  if (p->anyPending(&busy)) {
    report(busy, Severity::Error, "VUID-vkResetCommandPool-commandPool-00040",
           "vkResetCommandPool: a command buffer of the pool is still pending execution");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (CommandBuffer* cb : p->buffers) cb->reset((flags & VK_COMMAND_POOL_RESET_RELEASE_RESOURCES_BIT) != 0);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_TrimCommandPool(VkDevice device, VkCommandPool commandPool, VkCommandPoolTrimFlags) {
  CommandPool* p = livePool(device, commandPool, "vkTrimCommandPool", "VUID-vkTrimCommandPool-commandPool-parameter");
  if (!p) return;
  // Returns unused memory: command buffers in the initial state give back their command storage.
  for (CommandBuffer* cb : p->buffers)
    if (cb->currentState() == CommandBuffer::State::Initial) cb->commands.shrink_to_fit();
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_AllocateCommandBuffers(VkDevice device,
                                                           const VkCommandBufferAllocateInfo* pAllocateInfo,
                                                           VkCommandBuffer* pCommandBuffers) {
  Device* dev = fromHandleUnchecked<Device>(device);
  CommandPool* p = livePool(device, pAllocateInfo->commandPool, "vkAllocateCommandBuffers",
                            "VUID-VkCommandBufferAllocateInfo-commandPool-parameter");
  if (!p) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-VkCommandBufferAllocateInfo-level-parameter
  if (pAllocateInfo->level != VK_COMMAND_BUFFER_LEVEL_PRIMARY &&
      pAllocateInfo->level != VK_COMMAND_BUFFER_LEVEL_SECONDARY) {
    report(p, Severity::Error, "VUID-VkCommandBufferAllocateInfo-level-parameter",
           "vkAllocateCommandBuffers: level %d is not a VkCommandBufferLevel", (int)pAllocateInfo->level);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (uint32_t i = 0; i < pAllocateInfo->commandBufferCount; ++i) {
    CommandBuffer* cb =
        createObject<CommandBuffer>(p->alloc(), VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, p, pAllocateInfo->level);
    if (!cb) {
      for (uint32_t k = 0; k < i; ++k) {
        p->freeBuffer(fromHandleUnchecked<CommandBuffer>(pCommandBuffers[k]));
      }
      for (uint32_t k = 0; k < pAllocateInfo->commandBufferCount; ++k) pCommandBuffers[k] = VK_NULL_HANDLE;
      return VK_ERROR_OUT_OF_HOST_MEMORY;
    }
    p->buffers.insert(cb);
    pCommandBuffers[i] = toHandle(cb);
  }
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_FreeCommandBuffers(VkDevice device, VkCommandPool commandPool,
                                                   uint32_t commandBufferCount,
                                                   const VkCommandBuffer* pCommandBuffers) {
  CommandPool* p =
      livePool(device, commandPool, "vkFreeCommandBuffers", "VUID-vkFreeCommandBuffers-commandPool-parameter");
  if (!p) return;
  std::vector<CommandBuffer*> cbs;
  for (uint32_t i = 0; i < commandBufferCount; ++i) {
    if (!pCommandBuffers[i]) continue;
    CommandBuffer* cb = fromHandle<CommandBuffer>(pCommandBuffers[i]);
    // VUID-vkFreeCommandBuffers-pCommandBuffers-00048, VUID-vkFreeCommandBuffers-pCommandBuffers-parent
    if (!cb || cb->pool != p) {
      report(
          p, Severity::Error,
          cb ? "VUID-vkFreeCommandBuffers-pCommandBuffers-parent" : "VUID-vkFreeCommandBuffers-pCommandBuffers-00048",
          "vkFreeCommandBuffers: pCommandBuffers[%u] 0x%llx is not a live command buffer of this pool", i,
          (unsigned long long)rawHandle(pCommandBuffers[i]));
      return;
    }
    // VUID-vkFreeCommandBuffers-pCommandBuffers-00047
    if (cb->currentState() == CommandBuffer::State::Pending) {
      report(cb, Severity::Error, "VUID-vkFreeCommandBuffers-pCommandBuffers-00047",
             "vkFreeCommandBuffers: pCommandBuffers[%u] is pending execution", i);
      return;
    }
    cbs.push_back(cb);
  }
  for (CommandBuffer* cb : cbs)
    if (p->buffers.count(cb)) p->freeBuffer(cb);  // (the same handle may appear twice)
}

}  // extern "C"
