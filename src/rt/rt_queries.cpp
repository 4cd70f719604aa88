// Queries on ray tracing pipelines (group handles, capture/replay data, stack sizes) and the stack-size command.
#include <cstring>

#include "rt/group_handles.hpp"
#include "rt/rt_pipeline.hpp"
#include "runtime/alloc.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;
using namespace vkrt::rt;

namespace {

// The checks shared by both handle queries; `capture` selects the capture/replay variant's VUIDs.
RayTracingPipeline* checkHandleQuery(Device* dev, VkPipeline pipeline, uint32_t firstGroup, uint32_t groupCount,
                                     size_t dataSize, bool capture) {
  const char* cmd =
      capture ? "vkGetRayTracingCaptureReplayShaderGroupHandlesKHR" : "vkGetRayTracingShaderGroupHandlesKHR";
  Pipeline* base = fromHandle<Pipeline>(pipeline);
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-parameter / ...CaptureReplay...-pipeline-parameter
  if (!base) {
    report(dev, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-parameter"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-parameter",
           "%s: pipeline 0x%llx is not a live VkPipeline", cmd, (unsigned long long)rawHandle(pipeline));
    return nullptr;
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-parent / ...CaptureReplay...-pipeline-parent
  if (base->device != dev) {
    report(base, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-parent"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-parent",
           "%s: pipeline belongs to device 0x%llx, not 0x%llx", cmd, (unsigned long long)base->device->handleValue(),
           (unsigned long long)dev->handleValue());
    return nullptr;
  }
  RayTracingPipeline* p = asRayTracing(base);
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-04619 / VUID-...CaptureReplay...-pipeline-04620
  if (!p) {
    report(base, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-04620"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-04619",
           "%s: pipeline has bind point %d, not VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR", cmd, (int)base->bindPoint);
    return nullptr;
  }
  if (capture) {
    // VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-rayTracingPipelineShaderGroupHandleCaptureReplay-03606
    if (!dev->enabled(Feature::rayTracingPipelineShaderGroupHandleCaptureReplay)) {
      report(p, Severity::Error,
             "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-rayTracingPipelineShaderGroupHandleCaptureReplay-"
             "03606",
             "%s: the rayTracingPipelineShaderGroupHandleCaptureReplay feature is not enabled", cmd);
      return nullptr;
    }
    // VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-03607
    if (!(p->createFlags & VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR)) {
      report(
          p, Severity::Error, "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-03607",
          "%s: pipeline was created without VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR "
          "(flags 0x%x)",
          cmd, p->createFlags);
      return nullptr;
    }
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-07828 / VUID-...CaptureReplay...-pipeline-07829
  if (p->isLibrary() && !dev->enabled(Feature::pipelineLibraryGroupHandles)) {
    // The extension enabled without its feature is what an application sees when a layer that predates
    // VK_EXT_pipeline_library_group_handles copies vkCreateDevice's pNext chain without the structure it does not
    // know (GFXReconstruct 0.9.18 does): the message says so, as that is the likely cause.
    const bool extensionOnly = dev->extensionEnabled("VK_EXT_pipeline_library_group_handles");
    report(p, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-pipeline-07829"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-pipeline-07828",
           "%s: pipeline is a library (VK_PIPELINE_CREATE_LIBRARY_BIT_KHR) and the pipelineLibraryGroupHandles "
           "feature is not enabled%s",
           cmd,
           extensionOnly ? ": VK_EXT_pipeline_library_group_handles is enabled on the device, but vkCreateDevice "
                           "received no VkPhysicalDevicePipelineLibraryGroupHandlesFeaturesEXT with "
                           "pipelineLibraryGroupHandles = VK_TRUE (a layer that does not know the extension, such as "
                           "GFXReconstruct 0.9.18, drops that structure from the chain it passes on)"
                         : "");
    return nullptr;
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-firstGroup-04050 / VUID-...CaptureReplay...-firstGroup-04051
  if (firstGroup >= p->groupCount()) {
    report(p, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-firstGroup-04051"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-firstGroup-04050",
           "%s: firstGroup %u is not less than the pipeline's %u groups", cmd, firstGroup, p->groupCount());
    return nullptr;
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-firstGroup-02419 / VUID-...CaptureReplay...-firstGroup-03483
  if (uint64_t(firstGroup) + groupCount > p->groupCount()) {
    report(p, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-firstGroup-03483"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-firstGroup-02419",
           "%s: firstGroup %u + groupCount %u exceeds the pipeline's %u groups", cmd, firstGroup, groupCount,
           p->groupCount());
    return nullptr;
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-dataSize-arraylength / ...CaptureReplay...-dataSize-arraylength
  if (dataSize == 0) {
    report(p, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-dataSize-arraylength"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-dataSize-arraylength",
           "%s: dataSize is 0", cmd);
    return nullptr;
  }
  // VUID-vkGetRayTracingShaderGroupHandlesKHR-dataSize-02420 / VUID-...CaptureReplay...-dataSize-03484
  uint64_t each = capture ? kCaptureSize : kHandleSize;
  if (dataSize < each * groupCount) {
    report(p, Severity::Error,
           capture ? "VUID-vkGetRayTracingCaptureReplayShaderGroupHandlesKHR-dataSize-03484"
                   : "VUID-vkGetRayTracingShaderGroupHandlesKHR-dataSize-02420",
           "%s: dataSize %zu is less than %llu bytes x groupCount %u = %llu", cmd, dataSize, (unsigned long long)each,
           groupCount, (unsigned long long)(each * groupCount));
    return nullptr;
  }
  return p;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetRayTracingShaderGroupHandlesKHR(VkDevice device, VkPipeline pipeline,
                                                                       uint32_t firstGroup, uint32_t groupCount,
                                                                       size_t dataSize, void* pData) {
  Device* dev = fromHandleUnchecked<Device>(device);
  RayTracingPipeline* p = checkHandleQuery(dev, pipeline, firstGroup, groupCount, dataSize, false);
  if (!p) return VK_ERROR_VALIDATION_FAILED_EXT;
  auto* out = static_cast<uint8_t*>(pData);
  for (uint32_t g = 0; g < groupCount; ++g)
    std::memcpy(out + size_t(g) * kHandleSize, p->groups[firstGroup + g]->handle.data(), kHandleSize);
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetRayTracingCaptureReplayShaderGroupHandlesKHR(
    VkDevice device, VkPipeline pipeline, uint32_t firstGroup, uint32_t groupCount, size_t dataSize, void* pData) {
  Device* dev = fromHandleUnchecked<Device>(device);
  RayTracingPipeline* p = checkHandleQuery(dev, pipeline, firstGroup, groupCount, dataSize, true);
  if (!p) return VK_ERROR_VALIDATION_FAILED_EXT;
  auto* out = static_cast<uint8_t*>(pData);
  for (uint32_t g = 0; g < groupCount; ++g) {
    auto c = p->groups[firstGroup + g]->captureData();
    std::memcpy(out + size_t(g) * kCaptureSize, c.data(), kCaptureSize);
  }
  return VK_SUCCESS;
}

VKAPI_ATTR VkDeviceSize VKAPI_CALL vkrt_GetRayTracingShaderGroupStackSizeKHR(VkDevice device, VkPipeline pipeline,
                                                                             uint32_t group,
                                                                             VkShaderGroupShaderKHR groupShader) {
  Device* dev = fromHandleUnchecked<Device>(device);
  Pipeline* base = fromHandle<Pipeline>(pipeline);
  // VUID-vkGetRayTracingShaderGroupStackSizeKHR-pipeline-parameter
  if (!base) {
    report(dev, Severity::Error, "VUID-vkGetRayTracingShaderGroupStackSizeKHR-pipeline-parameter",
           "vkGetRayTracingShaderGroupStackSizeKHR: pipeline 0x%llx is not a live VkPipeline",
           (unsigned long long)rawHandle(pipeline));
    return 0;
  }
  RayTracingPipeline* p = asRayTracing(base);
  // VUID-vkGetRayTracingShaderGroupStackSizeKHR-pipeline-04622
  if (!p) {
    report(base, Severity::Error, "VUID-vkGetRayTracingShaderGroupStackSizeKHR-pipeline-04622",
           "vkGetRayTracingShaderGroupStackSizeKHR: pipeline has bind point %d, not a ray tracing pipeline",
           (int)base->bindPoint);
    return 0;
  }
  // VUID-vkGetRayTracingShaderGroupStackSizeKHR-group-03608
  if (group >= p->groupCount()) {
    report(p, Severity::Error, "VUID-vkGetRayTracingShaderGroupStackSizeKHR-group-03608",
           "vkGetRayTracingShaderGroupStackSizeKHR: group %u is not less than the pipeline's %u groups", group,
           p->groupCount());
    return 0;
  }
  // VUID-vkGetRayTracingShaderGroupStackSizeKHR-groupShader-parameter
  if (groupShader > VK_SHADER_GROUP_SHADER_INTERSECTION_KHR) {
    report(p, Severity::Error, "VUID-vkGetRayTracingShaderGroupStackSizeKHR-groupShader-parameter",
           "vkGetRayTracingShaderGroupStackSizeKHR: groupShader %d is not a VkShaderGroupShaderKHR value",
           (int)groupShader);
    return 0;
  }
  // VkShaderGroupShaderKHR is GENERAL 0, CLOSEST_HIT 1, ANY_HIT 2, INTERSECTION 3: the GroupShader order.
  const ShaderDesc* s = p->groups[group]->desc.shaders[groupShader].get();
  // VUID-vkGetRayTracingShaderGroupStackSizeKHR-groupShader-03609
  if (!s) {
    static const char* kNames[] = {"GENERAL", "CLOSEST_HIT", "ANY_HIT", "INTERSECTION"};
    report(p, Severity::Error, "VUID-vkGetRayTracingShaderGroupStackSizeKHR-groupShader-03609",
           "vkGetRayTracingShaderGroupStackSizeKHR: group %u has no VK_SHADER_GROUP_SHADER_%s_KHR shader "
           "(VK_SHADER_UNUSED_KHR)",
           group, kNames[groupShader]);
    return 0;
  }
  return s->stackSize();
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdSetRayTracingPipelineStackSizeKHR(VkCommandBuffer commandBuffer,
                                                                     uint32_t pipelineStackSize) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdSetRayTracingPipelineStackSizeKHR");
  if (!cb) return;
  // Kept for trace time: the tracing issue checks it against the bound pipeline (VUID-...-03610).
  cb->record([pipelineStackSize](ExecState& s) { s.rayTracingStackSize = pipelineStackSize; });
}

}  // extern "C"
