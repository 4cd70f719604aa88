#include "runtime/instance.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

DebugMessenger::DebugMessenger(Instance* inst, const VkDebugUtilsMessengerCreateInfoEXT& info)
    : Object(kType, inst, nullptr),
      severities(info.messageSeverity),
      types(info.messageType),
      callback(info.pfnUserCallback),
      userData(info.pUserData) {}

Instance::Instance(const VkInstanceCreateInfo& info) : Object(kType, this, nullptr) {
  apiVersion = (info.pApplicationInfo && info.pApplicationInfo->apiVersion) ? info.pApplicationInfo->apiVersion
                                                                            : VK_API_VERSION_1_0;
  for (uint32_t i = 0; i < info.enabledExtensionCount; ++i) enabledExtensions.insert(info.ppEnabledExtensionNames[i]);
  for (auto* s = static_cast<const VkBaseInStructure*>(info.pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT) {
      auto m = *reinterpret_cast<const VkDebugUtilsMessengerCreateInfoEXT*>(s);
      m.pNext = nullptr;
      creationMessengers.push_back(m);
    }
  }
}

Instance::~Instance() = default;

void Instance::addMessenger(DebugMessenger* m) {
  std::lock_guard lock(messengerMutex_);
  messengers_.push_back(m);
}

void Instance::removeMessenger(DebugMessenger* m) {
  std::lock_guard lock(messengerMutex_);
  messengers_.erase(std::remove(messengers_.begin(), messengers_.end(), m), messengers_.end());
}

bool Instance::hasMessengers() const {
  std::lock_guard lock(messengerMutex_);
  return !messengers_.empty() || (inCreateOrDestroy && !creationMessengers.empty());
}

bool Instance::dispatch(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                        const VkDebugUtilsMessengerCallbackDataEXT& data) const {
  bool any = false;
  std::vector<std::pair<PFN_vkDebugUtilsMessengerCallbackEXT, void*>> targets;
  {
    std::lock_guard lock(messengerMutex_);
    for (const DebugMessenger* m : messengers_) {
      any = true;
      if ((m->severities & severity) && (m->types & type) && m->callback)
        targets.emplace_back(m->callback, m->userData);
    }
  }
  for (const auto& m : creationMessengers) {
    if (!inCreateOrDestroy) break;  // VkInstanceCreateInfo's messengers only cover vkCreate/DestroyInstance
    any = true;
    if ((m.messageSeverity & severity) && (m.messageType & type) && m.pfnUserCallback)
      targets.emplace_back(m.pfnUserCallback, m.pUserData);
  }
  // Callbacks run outside the lock: a callback may create or destroy messengers.
  for (auto& [cb, user] : targets) cb(severity, type, &data, user);
  return any;
}

const std::vector<VkExtensionProperties>& instanceExtensions() {
  static const std::vector<VkExtensionProperties> exts = {
      {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_DEBUG_UTILS_SPEC_VERSION},
      {VK_KHR_GET_PHYSICAL_DEVICE_PROPERTIES_2_EXTENSION_NAME, VK_KHR_GET_PHYSICAL_DEVICE_PROPERTIES_2_SPEC_VERSION},
      {VK_KHR_EXTERNAL_MEMORY_CAPABILITIES_EXTENSION_NAME, VK_KHR_EXTERNAL_MEMORY_CAPABILITIES_SPEC_VERSION},
      {VK_KHR_EXTERNAL_FENCE_CAPABILITIES_EXTENSION_NAME, VK_KHR_EXTERNAL_FENCE_CAPABILITIES_SPEC_VERSION},
      {VK_KHR_EXTERNAL_SEMAPHORE_CAPABILITIES_EXTENSION_NAME, VK_KHR_EXTERNAL_SEMAPHORE_CAPABILITIES_SPEC_VERSION},
      {VK_KHR_DEVICE_GROUP_CREATION_EXTENSION_NAME, VK_KHR_DEVICE_GROUP_CREATION_SPEC_VERSION},
      // Presentation without a display (runtime/surface.cpp, runtime/swapchain.cpp).
      {VK_KHR_SURFACE_EXTENSION_NAME, VK_KHR_SURFACE_SPEC_VERSION},
      {VK_EXT_HEADLESS_SURFACE_EXTENSION_NAME, VK_EXT_HEADLESS_SURFACE_SPEC_VERSION},
  };
  return exts;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumerateInstanceVersion(uint32_t* pApiVersion) {
  *pApiVersion = VK_MAKE_API_VERSION(0, 1, 3, VK_HEADER_VERSION);
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumerateInstanceExtensionProperties(const char* pLayerName,
                                                                         uint32_t* pPropertyCount,
                                                                         VkExtensionProperties* pProperties) {
  if (pLayerName) return VK_ERROR_LAYER_NOT_PRESENT;
  const auto& exts = instanceExtensions();
  if (!pProperties) {
    *pPropertyCount = static_cast<uint32_t>(exts.size());
    return VK_SUCCESS;
  }
  uint32_t n = std::min<uint32_t>(*pPropertyCount, static_cast<uint32_t>(exts.size()));
  std::copy_n(exts.begin(), n, pProperties);
  *pPropertyCount = n;
  return n < exts.size() ? VK_INCOMPLETE : VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumerateInstanceLayerProperties(uint32_t* pPropertyCount, VkLayerProperties*) {
  *pPropertyCount = 0;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateInstance(const VkInstanceCreateInfo* pCreateInfo,
                                                   const VkAllocationCallbacks* pAllocator, VkInstance* pInstance) {
  for (uint32_t i = 0; i < pCreateInfo->enabledExtensionCount; ++i) {
    const char* name = pCreateInfo->ppEnabledExtensionNames[i];
    const auto& exts = instanceExtensions();
    bool known = std::any_of(exts.begin(), exts.end(),
                             [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
    if (!known) {
      report(nullptr, Severity::Error, nullptr, "vkCreateInstance: instance extension %s is not supported by vkrt",
             name);
      return VK_ERROR_EXTENSION_NOT_PRESENT;
    }
  }
  Instance* inst = createObject<Instance>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_INSTANCE, *pCreateInfo);
  if (!inst) return VK_ERROR_OUT_OF_HOST_MEMORY;
  inst->physicalDevice = createObject<PhysicalDevice>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_INSTANCE, inst);
  if (!inst->physicalDevice) {
    destroyObject(inst, pAllocator);
    return VK_ERROR_OUT_OF_HOST_MEMORY;
  }
  inst->inCreateOrDestroy = false;
  *pInstance = toHandle(inst);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyInstance(VkInstance instance, const VkAllocationCallbacks* pAllocator) {
  if (!instance) return;
  Instance* inst = fromHandle<Instance>(instance);
  if (!inst) {
    report(nullptr, Severity::Error, "VUID-vkDestroyInstance-instance-parameter",
           "vkDestroyInstance: 0x%llx is not a live VkInstance", (unsigned long long)rawHandle(instance));
    return;
  }
  inst->inCreateOrDestroy = true;
  destroyObject(inst->physicalDevice, pAllocator);
  destroyObject(inst, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumeratePhysicalDevices(VkInstance instance, uint32_t* pPhysicalDeviceCount,
                                                             VkPhysicalDevice* pPhysicalDevices) {
  Instance* inst = fromHandle<Instance>(instance);
  if (!inst) return VK_ERROR_INITIALIZATION_FAILED;
  if (!pPhysicalDevices) {
    *pPhysicalDeviceCount = 1;
    return VK_SUCCESS;
  }
  if (*pPhysicalDeviceCount < 1) return VK_INCOMPLETE;
  pPhysicalDevices[0] = toHandle(inst->physicalDevice);
  *pPhysicalDeviceCount = 1;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_EnumeratePhysicalDeviceGroups(VkInstance instance,
                                                                  uint32_t* pPhysicalDeviceGroupCount,
                                                                  VkPhysicalDeviceGroupProperties* pGroups) {
  Instance* inst = fromHandle<Instance>(instance);
  if (!inst) return VK_ERROR_INITIALIZATION_FAILED;
  if (!pGroups) {
    *pPhysicalDeviceGroupCount = 1;
    return VK_SUCCESS;
  }
  if (*pPhysicalDeviceGroupCount < 1) return VK_INCOMPLETE;
  pGroups[0].physicalDeviceCount = 1;
  pGroups[0].physicalDevices[0] = toHandle(inst->physicalDevice);
  pGroups[0].subsetAllocation = VK_FALSE;
  *pPhysicalDeviceGroupCount = 1;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDebugUtilsMessengerEXT(VkInstance instance,
                                                                 const VkDebugUtilsMessengerCreateInfoEXT* pCreateInfo,
                                                                 const VkAllocationCallbacks* pAllocator,
                                                                 VkDebugUtilsMessengerEXT* pMessenger) {
  Instance* inst = fromHandle<Instance>(instance);
  if (!inst) return VK_ERROR_INITIALIZATION_FAILED;
  auto* m = createObject<DebugMessenger>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, inst, *pCreateInfo);
  if (!m) return VK_ERROR_OUT_OF_HOST_MEMORY;
  inst->addMessenger(m);
  *pMessenger = toHandle(m);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDebugUtilsMessengerEXT(VkInstance instance, VkDebugUtilsMessengerEXT messenger,
                                                              const VkAllocationCallbacks* pAllocator) {
  if (!messenger) return;
  Instance* inst = fromHandle<Instance>(instance);
  DebugMessenger* m = fromHandle<DebugMessenger>(messenger);
  if (!inst || !m) {
    report(inst, Severity::Error, "VUID-vkDestroyDebugUtilsMessengerEXT-messenger-parameter",
           "vkDestroyDebugUtilsMessengerEXT: 0x%llx is not a live VkDebugUtilsMessengerEXT",
           (unsigned long long)rawHandle(messenger));
    return;
  }
  inst->removeMessenger(m);
  destroyObject(m, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL vkrt_SubmitDebugUtilsMessageEXT(VkInstance instance,
                                                           VkDebugUtilsMessageSeverityFlagBitsEXT messageSeverity,
                                                           VkDebugUtilsMessageTypeFlagsEXT messageTypes,
                                                           const VkDebugUtilsMessengerCallbackDataEXT* pCallbackData) {
  Instance* inst = fromHandle<Instance>(instance);
  if (inst) inst->dispatch(messageSeverity, messageTypes, *pCallbackData);
}

}  // extern "C"
