// The one place where vkrt defines Vulkan tokens newer than Debian 12's headers (1.3.239).
// Values come from the Vulkan registry; each block is skipped when the installed headers already have it.
#pragma once

#include <vulkan/vulkan_core.h>

#ifndef VK_EXT_pipeline_library_group_handles
#define VK_EXT_pipeline_library_group_handles 1
#define VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_SPEC_VERSION 1
#define VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_EXTENSION_NAME "VK_EXT_pipeline_library_group_handles"
// Extension number 499: 1000000000 + (499 - 1) * 1000 + 0.
#define VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT \
  static_cast<VkStructureType>(1000498000)
typedef struct VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT {
  VkStructureType sType;
  void* pNext;
  VkBool32 pipelineLibraryGroupHandles;
} VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT;
#endif

#ifndef VK_KHR_maintenance5
// VkBufferUsageFlags2CreateInfoKHR (VK_KHR_maintenance5, extension 471): vkrt does not advertise the extension, but
// reads the usage an application passes this way (the legacy usage bits are the low 32 bits of the new ones).
#define VK_STRUCTURE_TYPE_BUFFER_USAGE_FLAGS_2_CREATE_INFO_KHR static_cast<VkStructureType>(1000470006)
typedef struct VkBufferUsageFlags2CreateInfoKHR {
  VkStructureType sType;
  const void* pNext;
  uint64_t usage;
} VkBufferUsageFlags2CreateInfoKHR;
#endif

#ifndef VK_KHR_ray_tracing_position_fetch
#define VK_KHR_ray_tracing_position_fetch 1
#define VK_KHR_RAY_TRACING_POSITION_FETCH_SPEC_VERSION 1
#define VK_KHR_RAY_TRACING_POSITION_FETCH_EXTENSION_NAME "VK_KHR_ray_tracing_position_fetch"
// Extension number 482: 1000000000 + (482 - 1) * 1000 + 0.
#define VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_POSITION_FETCH_FEATURES_KHR \
  static_cast<VkStructureType>(1000481000)
#define VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_DATA_ACCESS_KHR \
  static_cast<VkBuildAccelerationStructureFlagBitsKHR>(0x800)
typedef struct VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR {
  VkStructureType sType;
  void* pNext;
  VkBool32 rayTracingPositionFetch;
} VkPhysicalDeviceRayTracingPositionFetchFeaturesKHR;
#endif
