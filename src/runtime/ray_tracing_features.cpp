#include "runtime/ray_tracing_features.hpp"

#include <cstring>


namespace vkrt::rt {

void appendExtensions(std::vector<VkExtensionProperties>& out) {
  out.push_back({VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_ACCELERATION_STRUCTURE_SPEC_VERSION});
  out.push_back({VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_DEFERRED_HOST_OPERATIONS_SPEC_VERSION});
  out.push_back({VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME, VK_KHR_RAY_TRACING_MAINTENANCE_1_SPEC_VERSION});
  out.push_back({VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_EXTENSION_NAME, VK_EXT_PIPELINE_LIBRARY_GROUP_HANDLES_SPEC_VERSION});
}

VkPhysicalDeviceRayTracingPipelinePropertiesKHR properties() {
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR};
  p.shaderGroupHandleSize = kShaderGroupHandleSize;
  p.maxRayRecursionDepth = 31;
  p.maxShaderGroupStride = 4096;
  p.shaderGroupBaseAlignment = 64;
  p.shaderGroupHandleCaptureReplaySize = kShaderGroupCaptureReplaySize;
  p.maxRayDispatchInvocationCount = 1u << 30;
  p.shaderGroupHandleAlignment = 32;
  p.maxRayHitAttributeSize = 32;
  return p;
}

bool fillFeature(VkBaseOutStructure* s) {
  switch (static_cast<uint32_t>(s->sType)) {
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR: {
      auto* f = reinterpret_cast<VkPhysicalDeviceRayTracingPipelineFeaturesKHR*>(s);
      f->rayTracingPipeline = VK_TRUE;
      f->rayTracingPipelineShaderGroupHandleCaptureReplay = VK_TRUE;
      f->rayTracingPipelineShaderGroupHandleCaptureReplayMixed = VK_TRUE;  // NVIDIA lacks it; vkrt has it
      f->rayTracingPipelineTraceRaysIndirect = VK_TRUE;
      f->rayTraversalPrimitiveCulling = VK_TRUE;
      return true;
    }
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT:
      reinterpret_cast<VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT*>(s)->pipelineLibraryGroupHandles = VK_TRUE;
      return true;
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR: {
      // Host commands and indirect builds are natural on a CPU: the device's memory is host memory.
      auto* f = reinterpret_cast<VkPhysicalDeviceAccelerationStructureFeaturesKHR*>(s);
      f->accelerationStructure = VK_TRUE;
      f->accelerationStructureCaptureReplay = VK_TRUE;
      f->accelerationStructureIndirectBuild = VK_TRUE;
      f->accelerationStructureHostCommands = VK_TRUE;
      f->descriptorBindingAccelerationStructureUpdateAfterBind = VK_TRUE;
      return true;
    }
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MAINTENANCE_1_FEATURES_KHR: {
      auto* f = reinterpret_cast<VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR*>(s);
      f->rayTracingMaintenance1 = VK_TRUE;
      f->rayTracingPipelineTraceRaysIndirect2 = VK_TRUE;
      return true;
    }
    default:
      return false;
  }
}

VkPhysicalDeviceAccelerationStructurePropertiesKHR accelerationStructureProperties() {
  VkPhysicalDeviceAccelerationStructurePropertiesKHR p{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
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

bool fillProperty(VkBaseOutStructure* s) {
  VkBaseOutStructure* next = s->pNext;
  if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR) {
    auto p = properties();
    std::memcpy(s, &p, sizeof(p));
  } else if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR) {
    auto p = accelerationStructureProperties();
    std::memcpy(s, &p, sizeof(p));
  } else {
    return false;
  }
  s->pNext = next;
  return true;
}

bool featureStructLayout(VkStructureType sType, size_t* size, size_t* end) {
  switch (static_cast<uint32_t>(sType)) {
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR:
      *size = sizeof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR);
      *end = offsetof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR, rayTraversalPrimitiveCulling) + sizeof(VkBool32);
      return true;
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR:
      *size = sizeof(VkPhysicalDeviceAccelerationStructureFeaturesKHR);
      *end = offsetof(VkPhysicalDeviceAccelerationStructureFeaturesKHR, descriptorBindingAccelerationStructureUpdateAfterBind) +
             sizeof(VkBool32);
      return true;
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MAINTENANCE_1_FEATURES_KHR:
      *size = sizeof(VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR);
      *end = offsetof(VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR, rayTracingPipelineTraceRaysIndirect2) + sizeof(VkBool32);
      return true;
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_LIBRARY_GROUP_HANDLES_FEATURES_EXT:
      *size = sizeof(VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT);
      *end = offsetof(VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT, pipelineLibraryGroupHandles) +
             sizeof(VkBool32);
      return true;
    default:
      return false;
  }
}

}  // namespace vkrt::rt
