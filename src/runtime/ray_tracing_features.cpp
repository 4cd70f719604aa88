#include "runtime/ray_tracing_features.hpp"

#include <cstdlib>
#include <cstring>


namespace vkrt::rt {

bool previewEnabled() {
  const char* v = std::getenv("VKRT_PREVIEW_RAY_TRACING");
  return v && std::strcmp(v, "1") == 0;
}

void appendExtensions(std::vector<VkExtensionProperties>& out) {
  if (!previewEnabled()) return;
  out.push_back({VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME, VK_KHR_DEFERRED_HOST_OPERATIONS_SPEC_VERSION});
  out.push_back({VK_KHR_PIPELINE_LIBRARY_EXTENSION_NAME, VK_KHR_PIPELINE_LIBRARY_SPEC_VERSION});
  out.push_back({VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_SPEC_VERSION});
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
  if (!previewEnabled()) return false;
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
    default:
      return false;
  }
}

bool fillProperty(VkBaseOutStructure* s) {
  if (!previewEnabled() || s->sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR) return false;
  VkBaseOutStructure* next = s->pNext;
  auto p = properties();
  std::memcpy(s, &p, sizeof(p));
  s->pNext = next;
  return true;
}

bool featureStructLayout(VkStructureType sType, size_t* size, size_t* end) {
  switch (static_cast<uint32_t>(sType)) {
    case VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR:
      *size = sizeof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR);
      *end = offsetof(VkPhysicalDeviceRayTracingPipelineFeaturesKHR, rayTraversalPrimitiveCulling) + sizeof(VkBool32);
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
