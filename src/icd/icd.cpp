// The loader–ICD interface (version 5 and later): the three vk_icd* exports and vkGet*ProcAddr.
#include <cstring>
#include <string>

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

// Whether every name of a provider ("A" or "A+B+...": gen_entrypoints.py) is there: a core version (vkrt
// implements them all), or an extension enabled on `device` or on its instance.
bool providerEnabled(const char* provider, const Device* device) {
  for (const char* p = provider; *p;) {
    const char* end = std::strchr(p, '+');
    const std::string name(p, end ? size_t(end - p) : std::strlen(p));
    const bool there = name.rfind("VK_VERSION_", 0) == 0 || device->enabledExtensions.count(name) ||
                       device->instance->enabledExtensions.count(name);
    if (!there) return false;
    p = end ? end + 1 : p + name.size();
  }
  return true;
}

// True when a command is available on `device`: one of its providers is (a core version vkrt implements, an
// extension enabled on the device or on its instance, or such names together).
bool enabledOn(const EntryPoint& e, const Device* device) {
  for (uint8_t i = 0; i < e.providerCount; ++i)
    if (providerEnabled(e.providers[i], device)) return true;
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
