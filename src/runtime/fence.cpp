#include "runtime/fence.hpp"

#include <chrono>
#include <vector>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace sync {

std::mutex& mutex() {
  static std::mutex* m = new std::mutex;  // never destroyed: queue workers may outlive static destruction
  return *m;
}

std::condition_variable& changed() {
  static std::condition_variable* cv = new std::condition_variable;
  return *cv;
}

bool waitFor(std::unique_lock<std::mutex>& lock, uint64_t timeoutNs, const std::function<bool()>& ready) {
  if (ready()) return true;
  if (timeoutNs == 0) return false;
  // About 292 years: anything longer cannot be a steady_clock deadline, and is forever for every practical use.
  constexpr uint64_t kForever = uint64_t(INT64_MAX) / 2;
  if (timeoutNs >= kForever) {
    changed().wait(lock, ready);
    return true;
  }
  auto deadline = std::chrono::steady_clock::now() + std::chrono::nanoseconds(timeoutNs);
  return changed().wait_until(lock, deadline, ready);
}

void notifyAll() { changed().notify_all(); }

}  // namespace sync

Fence::Fence(Device* dev, const VkFenceCreateInfo& info)
    : Object(kType, dev->instance, dev), signaled((info.flags & VK_FENCE_CREATE_SIGNALED_BIT) != 0) {}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Resolves pFences into live fences; reports the first bad handle (naming `vuid`) and returns false.
bool liveFences(Device* dev, uint32_t count, const VkFence* handles, std::vector<Fence*>& out, const char* fn,
                const char* vuid, const char* countVuid) {
  // VUID-vkWaitForFences-fenceCount-arraylength, VUID-vkResetFences-fenceCount-arraylength
  if (count == 0) {
    report(dev, Severity::Error, countVuid, "%s: fenceCount must be greater than 0", fn);
    return false;
  }
  out.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    out[i] = fromHandle<Fence>(handles[i]);
    if (!out[i]) {
      report(dev, Severity::Error, vuid, "%s: pFences[%u] 0x%llx is not a live VkFence", fn, i,
             (unsigned long long)rawHandle(handles[i]));
      return false;
    }
  }
  return true;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateFence(VkDevice device, const VkFenceCreateInfo* pCreateInfo,
                                                const VkAllocationCallbacks* pAllocator, VkFence* pFence) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Fence* f = createObject<Fence>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo);
  if (!f) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pFence = toHandle(f);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyFence(VkDevice device, VkFence fence, const VkAllocationCallbacks* pAllocator) {
  if (!fence) return;
  Fence* f = fromHandle<Fence>(fence);
  if (!f) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyFence-fence-parameter",
           "vkDestroyFence: 0x%llx is not a live VkFence", (unsigned long long)rawHandle(fence));
    return;
  }
  {
    std::lock_guard lock(sync::mutex());
    // VUID-vkDestroyFence-fence-01120: the submission that signals it must have completed
    if (f->pendingOn) {
      report(f, Severity::Error, "VUID-vkDestroyFence-fence-01120",
             "vkDestroyFence: the fence is still associated with a submission that has not completed");
      return;
    }
  }
  destroyObject(f, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_ResetFences(VkDevice device, uint32_t fenceCount, const VkFence* pFences) {
  Device* dev = fromHandleUnchecked<Device>(device);
  std::vector<Fence*> fences;
  if (!liveFences(dev, fenceCount, pFences, fences, "vkResetFences", "VUID-vkResetFences-pFences-parameter",
                  "VUID-vkResetFences-fenceCount-arraylength"))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  std::lock_guard lock(sync::mutex());
  for (uint32_t i = 0; i < fenceCount; ++i) {
    // VUID-vkResetFences-pFences-01123: not associated with a submission that has not completed
    if (fences[i]->pendingOn) {
      report(fences[i], Severity::Error, "VUID-vkResetFences-pFences-01123",
             "vkResetFences: pFences[%u] is still associated with a submission that has not completed", i);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  for (Fence* f : fences) f->signaled = false;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetFenceStatus(VkDevice device, VkFence fence) {
  Fence* f = fromHandle<Fence>(fence);
  if (!f) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkGetFenceStatus-fence-parameter",
           "vkGetFenceStatus: 0x%llx is not a live VkFence", (unsigned long long)rawHandle(fence));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::lock_guard lock(sync::mutex());
  if (f->device->lost) return VK_ERROR_DEVICE_LOST;  // Lost Device
  return f->signaled ? VK_SUCCESS : VK_NOT_READY;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_WaitForFences(VkDevice device, uint32_t fenceCount, const VkFence* pFences,
                                                  VkBool32 waitAll, uint64_t timeout) {
  Device* dev = fromHandleUnchecked<Device>(device);
  std::vector<Fence*> fences;
  if (!liveFences(dev, fenceCount, pFences, fences, "vkWaitForFences", "VUID-vkWaitForFences-pFences-parameter",
                  "VUID-vkWaitForFences-fenceCount-arraylength"))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  std::unique_lock lock(sync::mutex());
  // Lost Device: a fence of a submission still completes (the queue drains without running anything), one that
  // was never submitted never will, so it counts as done; the wait then returns VK_ERROR_DEVICE_LOST.
  auto done = [&](const Fence* f) { return f->signaled || (dev->lost && !f->pendingOn); };
  bool ok = sync::waitFor(lock, timeout, [&] {
    if (waitAll) {
      for (Fence* f : fences)
        if (!done(f)) return false;
      return true;
    }
    for (Fence* f : fences)
      if (done(f)) return true;
    return false;
  });
  if (dev->lost) return VK_ERROR_DEVICE_LOST;
  return ok ? VK_SUCCESS : VK_TIMEOUT;
}

}  // extern "C"
