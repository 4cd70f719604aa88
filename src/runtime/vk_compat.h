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
