#include "runtime/semaphore.hpp"

#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/fence.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Semaphore::Semaphore(Device* dev, VkSemaphoreType t, uint64_t initialValue)
    : Object(kType, dev->instance, dev), type(t), value(initialValue) {}

bool Semaphore::waitOnQueue(uint64_t waitValue, const bool* abandon) {
  std::unique_lock lock(sync::mutex());
  sync::changed().wait(lock, [&] { return *abandon || (timeline() ? value >= waitValue : value != 0); });
  if (*abandon) return false;
  if (!timeline()) value = 0;  // a binary wait unsignals the semaphore
  return true;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

Semaphore* liveSemaphore(VkDevice device, VkSemaphore h, const char* fn, const char* vuid) {
  return liveOrReport<Semaphore>(fromHandle<Device>(device), h, fn, vuid);
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateSemaphore(VkDevice device, const VkSemaphoreCreateInfo* pCreateInfo,
                                                    const VkAllocationCallbacks* pAllocator, VkSemaphore* pSemaphore) {
  Device* dev = fromHandleUnchecked<Device>(device);
  VkSemaphoreType type = VK_SEMAPHORE_TYPE_BINARY;
  uint64_t initial = 0;
  if (auto* t =
          findInChain<VkSemaphoreTypeCreateInfo>(pCreateInfo->pNext, VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO)) {
    type = t->semaphoreType;
    initial = t->initialValue;
    // VUID-VkSemaphoreTypeCreateInfo-timelineSemaphore-03252
    if (type == VK_SEMAPHORE_TYPE_TIMELINE && !dev->enabled(Feature::timelineSemaphore)) {
      report(dev, Severity::Error, "VUID-VkSemaphoreTypeCreateInfo-timelineSemaphore-03252",
             "vkCreateSemaphore: a timeline semaphore needs the timelineSemaphore feature, which is not enabled");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkSemaphoreTypeCreateInfo-semaphoreType-03279
    if (type == VK_SEMAPHORE_TYPE_BINARY && initial != 0) {
      report(dev, Severity::Error, "VUID-VkSemaphoreTypeCreateInfo-semaphoreType-03279",
             "vkCreateSemaphore: a binary semaphore's initialValue must be 0, not %llu", (unsigned long long)initial);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkSemaphoreTypeCreateInfo-semaphoreType-parameter
    if (type != VK_SEMAPHORE_TYPE_BINARY && type != VK_SEMAPHORE_TYPE_TIMELINE) {
      report(dev, Severity::Error, "VUID-VkSemaphoreTypeCreateInfo-semaphoreType-parameter",
             "vkCreateSemaphore: semaphoreType %d is not a VkSemaphoreType", (int)type);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  Semaphore* s = createObject<Semaphore>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, type, initial);
  if (!s) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pSemaphore = toHandle(s);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroySemaphore(VkDevice device, VkSemaphore semaphore,
                                                 const VkAllocationCallbacks* pAllocator) {
  if (!semaphore) return;
  Semaphore* s = liveSemaphore(device, semaphore, "vkDestroySemaphore", "VUID-vkDestroySemaphore-semaphore-parameter");
  if (!s) return;
  {
    std::lock_guard lock(sync::mutex());
    // VUID-vkDestroySemaphore-semaphore-01137: every submitted batch that refers to it has completed
    if (s->inFlight) {
      report(s, Severity::Error, "VUID-vkDestroySemaphore-semaphore-01137",
             "vkDestroySemaphore: %u submitted batches that refer to the semaphore have not completed", s->inFlight);
      return;
    }
  }
  destroyObject(s, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetSemaphoreCounterValue(VkDevice device, VkSemaphore semaphore, uint64_t* pValue) {
  Semaphore* s = liveSemaphore(device, semaphore, "vkGetSemaphoreCounterValue",
                               "VUID-vkGetSemaphoreCounterValue-semaphore-parameter");
  if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkGetSemaphoreCounterValue-semaphore-03255
  if (!s->timeline()) {
    report(s, Severity::Error, "VUID-vkGetSemaphoreCounterValue-semaphore-03255",
           "vkGetSemaphoreCounterValue: the semaphore is binary, not a timeline semaphore");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::lock_guard lock(sync::mutex());
  *pValue = s->value;
  return s->device->lost ? VK_ERROR_DEVICE_LOST : VK_SUCCESS;  // Lost Device
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_SignalSemaphore(VkDevice device, const VkSemaphoreSignalInfo* pSignalInfo) {
  Semaphore* s = liveSemaphore(device, pSignalInfo->semaphore, "vkSignalSemaphore",
                               "VUID-VkSemaphoreSignalInfo-semaphore-parameter");
  if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-VkSemaphoreSignalInfo-semaphore-03257
  if (!s->timeline()) {
    report(s, Severity::Error, "VUID-VkSemaphoreSignalInfo-semaphore-03257",
           "vkSignalSemaphore: the semaphore is binary; only timeline semaphores are signaled from the host");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  {
    std::lock_guard lock(sync::mutex());
    // VUID-VkSemaphoreSignalInfo-value-03258
    if (pSignalInfo->value <= s->value) {
      report(s, Severity::Error, "VUID-VkSemaphoreSignalInfo-value-03258",
             "vkSignalSemaphore: value %llu is not greater than the current value %llu",
             (unsigned long long)pSignalInfo->value, (unsigned long long)s->value);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkSemaphoreSignalInfo-value-03259
    if (!s->pendingSignals.empty() && pSignalInfo->value >= *s->pendingSignals.begin()) {
      report(s, Severity::Error, "VUID-VkSemaphoreSignalInfo-value-03259",
             "vkSignalSemaphore: value %llu is not less than the pending signal operation's value %llu",
             (unsigned long long)pSignalInfo->value, (unsigned long long)*s->pendingSignals.begin());
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    s->value = pSignalInfo->value;
  }
  sync::notifyAll();
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_WaitSemaphores(VkDevice device, const VkSemaphoreWaitInfo* pWaitInfo,
                                                   uint64_t timeout) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkSemaphoreWaitInfo-semaphoreCount-arraylength
  if (pWaitInfo->semaphoreCount == 0) {
    report(dev, Severity::Error, "VUID-VkSemaphoreWaitInfo-semaphoreCount-arraylength",
           "vkWaitSemaphores: semaphoreCount must be greater than 0");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<Semaphore*> sems(pWaitInfo->semaphoreCount);
  for (uint32_t i = 0; i < pWaitInfo->semaphoreCount; ++i) {
    sems[i] = liveSemaphore(device, pWaitInfo->pSemaphores[i], "vkWaitSemaphores",
                            "VUID-VkSemaphoreWaitInfo-pSemaphores-parameter");
    if (!sems[i]) return VK_ERROR_VALIDATION_FAILED_EXT;
    // VUID-VkSemaphoreWaitInfo-pSemaphores-03256
    if (!sems[i]->timeline()) {
      report(sems[i], Severity::Error, "VUID-VkSemaphoreWaitInfo-pSemaphores-03256",
             "vkWaitSemaphores: pSemaphores[%u] is a binary semaphore; only timeline semaphores can be waited on", i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  const bool any = (pWaitInfo->flags & VK_SEMAPHORE_WAIT_ANY_BIT) != 0;
  std::unique_lock lock(sync::mutex());
  // Lost Device: signals already submitted still happen (the queues drain without running anything); a value no
  // pending signal reaches never will, so it counts as reached, and the wait returns VK_ERROR_DEVICE_LOST.
  bool ok = sync::waitFor(lock, timeout, [&] {
    for (uint32_t i = 0; i < pWaitInfo->semaphoreCount; ++i) {
      bool reached = sems[i]->value >= pWaitInfo->pValues[i] || (dev->lost && sems[i]->pendingSignals.empty());
      if (any && reached) return true;
      if (!any && !reached) return false;
    }
    return !any;
  });
  if (dev->lost) return VK_ERROR_DEVICE_LOST;
  return ok ? VK_SUCCESS : VK_TIMEOUT;
}

}  // extern "C"
