#include "runtime/private_data_slot.hpp"

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

PrivateDataSlot::PrivateDataSlot(Device* dev) : Object(kType, dev->instance, dev) {}

void PrivateDataSlot::set(const Object& object, uint64_t value) {
  std::lock_guard lock(mutex_);
  values_[object.serial] = value;
}

uint64_t PrivateDataSlot::get(const Object& object) const {
  std::lock_guard lock(mutex_);
  auto it = values_.find(object.serial);
  return it == values_.end() ? 0 : it->second;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

// The slot `h` of `dev`, or null after reporting (VUID-vk{Set,Get}PrivateData-privateDataSlot-parameter / -parent).
PrivateDataSlot* slotOf(Device* dev, VkPrivateDataSlot h, const char* fn, const char* vuidLive,
                        const char* vuidParent) {
  PrivateDataSlot* slot = liveOrReport<PrivateDataSlot>(dev, h, fn, vuidLive);
  if (slot && slot->device != dev) {
    report(dev, Severity::Error, vuidParent, "%s: privateDataSlot 0x%llx belongs to another device", fn,
           (unsigned long long)rawHandle(h));
    return nullptr;
  }
  return slot;
}

// Whether `o` is `dev` or one of its children.
bool ofDevice(const Object& o, const Device* dev) { return &o == dev || o.device == dev; }

}  // namespace

extern "C" {

// Also vkCreatePrivateDataSlotEXT (VK_EXT_private_data), an alias. Slots reserved at device creation
// (VkDevicePrivateDataCreateInfo) need nothing: a slot is a map, and any number can be created later.
VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreatePrivateDataSlot(VkDevice device, const VkPrivateDataSlotCreateInfo*,
                                                          const VkAllocationCallbacks* pAllocator,
                                                          VkPrivateDataSlot* pPrivateDataSlot) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkCreatePrivateDataSlot-privateData-04564
  if (!dev->enabled(Feature::privateData)) {
    report(dev, Severity::Error, "VUID-vkCreatePrivateDataSlot-privateData-04564",
           "vkCreatePrivateDataSlot: the privateData feature is not enabled");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* slot = createObject<PrivateDataSlot>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev);
  if (!slot) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pPrivateDataSlot = toHandle(slot);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyPrivateDataSlot(VkDevice device, VkPrivateDataSlot privateDataSlot,
                                                       const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChild<PrivateDataSlot>(device, privateDataSlot, pAllocator, "vkDestroyPrivateDataSlot",
                                      "VUID-vkDestroyPrivateDataSlot-privateDataSlot-parameter");
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_SetPrivateData(VkDevice device, VkObjectType objectType, uint64_t objectHandle,
                                                   VkPrivateDataSlot privateDataSlot, uint64_t data) {
  const char* fn = "vkSetPrivateData";
  Device* dev = fromHandleUnchecked<Device>(device);
  PrivateDataSlot* slot = slotOf(dev, privateDataSlot, fn, "VUID-vkSetPrivateData-privateDataSlot-parameter",
                                 "VUID-vkSetPrivateData-privateDataSlot-parent");
  if (!slot) return VK_ERROR_VALIDATION_FAILED_EXT;
  const Object* o = findObject(objectHandle, objectType);
  // VUID-vkSetPrivateData-objectHandle-04017: a live object of objectType
  if (!o) {
    report(dev, Severity::Error, "VUID-vkSetPrivateData-objectHandle-04017",
           "%s: objectHandle 0x%llx is not a live %s (objectType %d)", fn, (unsigned long long)objectHandle,
           objectTypeName(objectType), (int)objectType);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkSetPrivateData-objectHandle-04016: the device or one of its children
  if (!ofDevice(*o, dev)) {
    report(dev, Severity::Error, "VUID-vkSetPrivateData-objectHandle-04016",
           "%s: objectHandle 0x%llx (%s) is neither the device nor one of its children", fn,
           (unsigned long long)objectHandle, objectTypeName(objectType));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  slot->set(*o, data);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPrivateData(VkDevice device, VkObjectType objectType, uint64_t objectHandle,
                                               VkPrivateDataSlot privateDataSlot, uint64_t* pData) {
  const char* fn = "vkGetPrivateData";
  Device* dev = fromHandleUnchecked<Device>(device);
  *pData = 0;
  PrivateDataSlot* slot = slotOf(dev, privateDataSlot, fn, "VUID-vkGetPrivateData-privateDataSlot-parameter",
                                 "VUID-vkGetPrivateData-privateDataSlot-parent");
  // An object that is not live has no value: 0 (the specification asks nothing more of the handle).
  const Object* o = slot ? findObject(objectHandle, objectType) : nullptr;
  if (!o) return;
  // VUID-vkGetPrivateData-objectType-04018: the device or a type whose parent is the device
  if (!ofDevice(*o, dev)) {
    report(dev, Severity::Error, "VUID-vkGetPrivateData-objectType-04018",
           "%s: objectHandle 0x%llx (%s) is neither the device nor one of its children", fn,
           (unsigned long long)objectHandle, objectTypeName(objectType));
    return;
  }
  *pData = slot->get(*o);
}

}  // extern "C"
