// What vkrt advertises for ray tracing: the extensions (VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline,
// VK_KHR_ray_tracing_maintenance1, VK_KHR_pipeline_library, VK_EXT_pipeline_library_group_handles,
// VK_KHR_deferred_host_operations), their features and properties, and their pNext structures.
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/vk.hpp"

namespace vkrt::rt {

// Appends the ray tracing extensions.
void appendExtensions(std::vector<VkExtensionProperties>& out);

// Fills a ray tracing feature / property structure of a VkPhysicalDeviceFeatures2 / Properties2 chain.
// Returns false (structure untouched) for other structures.
bool fillFeature(VkBaseOutStructure* s);
bool fillProperty(VkBaseOutStructure* s);

// For VkDeviceCreateInfo checking: the size of a ray tracing feature structure and the offset just past its
// last VkBool32. Returns false for other structures.
bool featureStructLayout(VkStructureType sType, size_t* size, size_t* end);

// Sizes of a shader-group handle and of its capture/replay data (src/rt/group_handles.hpp defines their contents).
inline constexpr uint32_t kShaderGroupHandleSize = 32;
inline constexpr uint32_t kShaderGroupCaptureReplaySize = 64;

// The properties (NVIDIA's values where the spec leaves the choice).
VkPhysicalDeviceRayTracingPipelinePropertiesKHR properties();
VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationStructureProperties();

}  // namespace vkrt::rt
