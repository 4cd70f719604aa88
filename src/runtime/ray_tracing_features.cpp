#include "runtime/ray_tracing_features.hpp"

#include <cstring>

namespace vkrt {

void appendRayTracingExtensions(std::vector<VkExtensionProperties>& out) {
  out.push_back({VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_SPEC_VERSION});
  out.push_back({VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_DEFERRED_HOST_OPERATIONS_SPEC_VERSION});
  out.push_back({VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME, VK_KHR_RAY_TRACING_MAINTENANCE_1_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_QUERY_EXTENSION_NAME, VK_KHR_RAY_QUERY_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_POSITION_FETCH_EXTENSION_NAME, VK_KHR_RAY_TRACING_POSITION_FETCH_SPEC_VERSION});
  out.push_back(
      {VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_EXTENSION_NAME, VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_SPEC_VERSION});
  // On the same pipelines, structures and launches (rt/rt_pipeline.cpp, runtime/acceleration_structure_nv.cpp,
  // rt/trace_rays.cpp).
  out.push_back({VK_NV_RAY_TRACING_EXTENSION_NAME, VK_NV_RAY_TRACING_SPEC_VERSION});
}

VkPhysicalDeviceRayTracingPipelinePropertiesKHR rayTracingPipelineProperties() {
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR p{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  p.shaderGroupHandleSize = kShaderGroupHandleSize;
  p.maxRayRecursionDepth = 31;
  p.maxShaderGroupStride = 4096;
  p.shaderGroupBaseAlignment = 64;
  p.shaderGroupHandleCaptureReplaySize = kShaderGroupCaptureReplaySize;
  p.maxRayDispatchInvocationCount = 1u << 30;
  p.shaderGroupHandleAlignment = 1;  // handles are read byte by byte; a CPU needs no alignment of records
  p.maxRayHitAttributeSize = 32;
  return p;
}

VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationStructureProperties() {
  VkPhysicalDeviceAccelerationStructurePropertiesKHR p{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  p.maxGeometryCount = (1u << 24) - 1;
  p.maxInstanceCount = (1u << 24) - 1;
  p.maxPrimitiveCount = (1u << 29) - 1;
  p.maxPerStageDescriptorAccelerationStructures = 1u << 20;
  p.maxPerStageDescriptorUpdateAfterBindAccelerationStructures = 1u << 20;
  p.maxDescriptorSetAccelerationStructures = 1u << 20;
  p.maxDescriptorSetUpdateAfterBindAccelerationStructures = 1u << 20;
  p.minAccelerationStructureScratchOffsetAlignment = 128;
  return p;
}

VkPhysicalDeviceRayTracingPropertiesNV rayTracingPropertiesNV() {
  // The NV path shares the KHR one's groups, handles and structures: the same figures under the NV names.
  const VkPhysicalDeviceRayTracingPipelinePropertiesKHR k = rayTracingPipelineProperties();
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR a = accelerationStructureProperties();
  VkPhysicalDeviceRayTracingPropertiesNV p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV};
  p.shaderGroupHandleSize = k.shaderGroupHandleSize;
  p.maxRecursionDepth = k.maxRayRecursionDepth;
  p.maxShaderGroupStride = k.maxShaderGroupStride;
  p.shaderGroupBaseAlignment = k.shaderGroupBaseAlignment;
  p.maxGeometryCount = a.maxGeometryCount;
  p.maxInstanceCount = a.maxInstanceCount;
  p.maxTriangleCount = a.maxPrimitiveCount;
  p.maxDescriptorSetAccelerationStructures = a.maxDescriptorSetAccelerationStructures;
  return p;
}

}  // namespace vkrt
