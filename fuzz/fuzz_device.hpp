// What the API-level fuzz targets share: an instance and a device made through vkrt's own entry points (no
// loader: the targets link vkrt's layer objects), created once per process, with the ray tracing features on.
// VKRT_LOG is set to "none" (unless the caller set it): a fuzzer's millions of reported errors are expected and
// printing them would be most of its time.
#pragma once

#include <cstdlib>

#include "vkrt_entrypoints.h"

namespace vkrt::fuzz {

struct FuzzDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
};

// A new instance and device (aborts when vkrt refuses them: the fuzzer cannot go on).
inline FuzzDevice makeFuzzDevice() {
  setenv("VKRT_LOG", "none", 0);
  FuzzDevice f;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (vkrt_CreateInstance(&ici, nullptr, &f.instance) != VK_SUCCESS) std::abort();
  uint32_t n = 1;
  VkResult r = vkrt_EnumeratePhysicalDevices(f.instance, &n, &f.physical);
  if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || !f.physical) std::abort();
  VkPhysicalDeviceBufferDeviceAddressFeatures bda{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_BUFFER_DEVICE_ADDRESS_FEATURES};
  bda.bufferDeviceAddress = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &bda};
  as.accelerationStructure = VK_TRUE;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR,
                                                   &as};
  rt.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceRayQueryFeaturesKHR rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR, &rt};
  rq.rayQuery = VK_TRUE;
  const char* extensions[] = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                              VK_KHR_RAY_QUERY_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME,
                              VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  float priority = 1;
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &rq};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &q;
  dci.enabledExtensionCount = sizeof extensions / sizeof extensions[0];
  dci.ppEnabledExtensionNames = extensions;
  if (vkrt_CreateDevice(f.physical, &dci, nullptr, &f.device) != VK_SUCCESS) std::abort();
  vkrt_GetDeviceQueue(f.device, 0, 0, &f.queue);
  return f;
}

inline void destroyFuzzDevice(FuzzDevice& f) {
  vkrt_DestroyDevice(f.device, nullptr);
  vkrt_DestroyInstance(f.instance, nullptr);
  f = FuzzDevice{};
}

// The process's device (never destroyed).
inline const FuzzDevice& fuzzDevice() {
  static FuzzDevice d = makeFuzzDevice();
  return d;
}

}  // namespace vkrt::fuzz
