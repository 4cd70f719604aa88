// Handle checks shared by the entry points: a handle that is not a live object of the expected type is
// reported through the funnel (naming the command, the handle and the VUID) instead of dereferenced.
#pragma once

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"

namespace vkrt {

// The live T behind `h`; otherwise reports "<fn>: 0x... is not a live VkX" about `reportTo` and returns null.
template <class T>
T* liveOrReport(const Object* reportTo, typename T::Handle h, const char* fn, const char* vuid) {
  T* obj = fromHandle<T>(h);
  if (!obj)
    report(reportTo, Severity::Error, vuid, "%s: 0x%llx is not a live %s", fn,
           static_cast<unsigned long long>(rawHandle(h)), objectTypeName(T::kType));
  return obj;
}

// The body of vkDestroyXxx/vkFreeXxx for a device child: VK_NULL_HANDLE is ignored, a handle that is not a
// live T is reported (about the device), anything else is destroyed with the application's allocator.
template <class T>
void destroyDeviceChild(VkDevice device, typename T::Handle h, const VkAllocationCallbacks* allocator, const char* fn,
                        const char* vuid) {
  if (!h) return;
  if (T* obj = liveOrReport<T>(fromHandle<Device>(device), h, fn, vuid)) destroyObject(obj, allocator);
}

// Destroys `obj` now, or, while queue work submitted before is pending, once that work has completed
// (Device::deferIfPending: a pending command buffer that refers to it is reported under `pendingVuid`).
template <class T>
void destroyWhenIdle(T* obj, const VkAllocationCallbacks* allocator, const char* fn, const char* pendingVuid) {
  VkAllocationCallbacks copy{};
  const bool hasAllocator = allocator != nullptr;
  if (hasAllocator) copy = *allocator;
  if (!obj->device->deferIfPending(
          obj, [obj, copy, hasAllocator] { destroyObject(obj, hasAllocator ? &copy : nullptr); }, fn, pendingVuid))
    destroyObject(obj, allocator);
}

// destroyDeviceChild for the objects that pending work may still use (destroyWhenIdle).
template <class T>
void destroyDeviceChildWhenIdle(VkDevice device, typename T::Handle h, const VkAllocationCallbacks* allocator,
                                const char* fn, const char* vuid, const char* pendingVuid) {
  if (!h) return;
  if (T* obj = liveOrReport<T>(fromHandle<Device>(device), h, fn, vuid))
    destroyWhenIdle(obj, allocator, fn, pendingVuid);
}

}  // namespace vkrt
