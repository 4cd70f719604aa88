// The loader–ICD interface (version 5 and later): the three vk_icd* exports and vkGet*ProcAddr.
#include <cstring>

#include "icd/entrypoint_table.hpp"
#include "runtime/device.hpp"
#include "runtime/instance.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

const EntryPoint* findEntryPoint(const char* name) {
  if (!name) return nullptr;
  size_t lo = 0, hi = kEntryPointCount;
  while (lo < hi) {
    size_t mid = (lo + hi) / 2;
    int c = std::strcmp(kEntryPoints[mid].name, name);
    if (c == 0) return &kEntryPoints[mid];
    if (c < 0) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return nullptr;
}

namespace {

// True when a command is available on `device`: it belongs to a core version vkrt implements, or to an
// extension enabled on the device or on its instance.
bool enabledOn(const EntryPoint& e, const Device* device) {
  for (uint8_t i = 0; i < e.providerCount; ++i) {
    const char* p = e.providers[i];
    if (std::strncmp(p, "VK_VERSION_", 11) == 0) return true;
    if (device->enabledExtensions.count(p) || device->instance->enabledExtensions.count(p)) return true;
  }
  return false;
}

}  // namespace
}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkrt_GetInstanceProcAddr(VkInstance instance, const char* pName) {
  const EntryPoint* e = findEntryPoint(pName);
  if (!e || !e->fn) return nullptr;
  if (e->level == EntryLevel::Global) return e->fn;
  return instance ? e->fn : nullptr;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkrt_GetDeviceProcAddr(VkDevice device, const char* pName) {
  const EntryPoint* e = findEntryPoint(pName);
  if (!e || !e->fn || e->level != EntryLevel::Device) return nullptr;
  Device* dev = fromHandle<Device>(device);
  if (!dev || !enabledOn(*e, dev)) return nullptr;
  return e->fn;
}

__attribute__((visibility("default"))) VKAPI_ATTR VkResult VKAPI_CALL
vk_icdNegotiateLoaderICDInterfaceVersion(uint32_t* pSupportedVersion) {
  // Version 5: the loader may use vk_icdGetPhysicalDeviceProcAddr and handles apiVersion 1.x checks.
  if (*pSupportedVersion > 5) *pSupportedVersion = 5;
  return *pSupportedVersion < 5 ? VK_ERROR_INCOMPATIBLE_DRIVER : VK_SUCCESS;
}

__attribute__((visibility("default"))) VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL
vk_icdGetInstanceProcAddr(VkInstance instance, const char* pName) {
  return vkrt_GetInstanceProcAddr(instance, pName);
}

__attribute__((visibility("default"))) VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL
vk_icdGetPhysicalDeviceProcAddr(VkInstance, const char* pName) {
  const EntryPoint* e = findEntryPoint(pName);
  if (!e || e->level != EntryLevel::PhysicalDevice) return nullptr;
  return e->fn;
}

}  // extern "C"
