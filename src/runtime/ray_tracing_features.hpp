// What vkrt advertises for ray tracing: the extensions (VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline,
// VK_KHR_ray_tracing_maintenance1, VK_KHR_pipeline_library, VK_EXT_pipeline_library_group_handles,
// VK_KHR_deferred_host_operations, VK_NV_ray_tracing) and their properties. (Their features are in
// runtime/supported_features.cpp.)
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/vk.hpp"

namespace vkrt {

// Appends the ray tracing extensions.
void appendRayTracingExtensions(std::vector<VkExtensionProperties>& out);

// Sizes of a shader-group handle and of its capture/replay data (src/rt/group_handles.hpp defines their contents).
inline constexpr uint32_t kShaderGroupHandleSize = 32;
inline constexpr uint32_t kShaderGroupCaptureReplaySize = 64;

// The properties (NVIDIA's values where the spec leaves the choice).
VkPhysicalDeviceRayTracingPipelinePropertiesKHR rayTracingPipelineProperties();
VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationStructureProperties();
// VK_NV_ray_tracing's properties: the same figures (its pipelines and structures are the KHR ones).
VkPhysicalDeviceRayTracingPropertiesNV rayTracingPropertiesNV();

}  // namespace vkrt
