#include "runtime/compute_pipeline.hpp"

#include <chrono>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_module.hpp"
#include "runtime/shader_stage.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

constexpr VkPipelineCreateFlags kForbiddenFlags[][2] = {
    {VK_PIPELINE_CREATE_LIBRARY_BIT_KHR, 3364},
    {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR, 3365},
    {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR, 3366},
    {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR, 3367},
    {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_INTERSECTION_SHADERS_BIT_KHR, 3368},
    {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR, 3369},
    {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR, 3370},
    {VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR, 3576},
};

// Creates pipeline i; returns its result (pipeline set only on success).
VkResult createOne(Device* dev, PipelineCache* cache, const VkComputePipelineCreateInfo& ci, uint32_t i,
                   const VkAllocationCallbacks* alloc, VkPipeline* out) {
  const char* fn = "vkCreateComputePipelines";
  const auto start = std::chrono::steady_clock::now();
  for (const auto& f : kForbiddenFlags) {
    // VUID-VkComputePipelineCreateInfo-flags-03364 .. -03576 (the ray tracing and library flags)
    if (ci.flags & f[0]) {
      char vuid[64];
      std::snprintf(vuid, sizeof vuid, "VUID-VkComputePipelineCreateInfo-flags-0%u", unsigned(f[1]));
      report(dev, Severity::Error, vuid,
             "%s: pCreateInfos[%u].flags (0x%x) contains 0x%x, which compute pipelines must not use", fn, i, ci.flags,
             f[0]);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-VkComputePipelineCreateInfo-stage-00701
  if (ci.stage.stage != VK_SHADER_STAGE_COMPUTE_BIT) {
    report(dev, Severity::Error, "VUID-VkComputePipelineCreateInfo-stage-00701",
           "%s: pCreateInfos[%u].stage.stage is 0x%x, not VK_SHADER_STAGE_COMPUTE_BIT", fn, i, ci.stage.stage);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkComputePipelineCreateInfo-layout-parameter
  PipelineLayout* layout = fromHandle<PipelineLayout>(ci.layout);
  if (!layout) {
    report(dev, Severity::Error, "VUID-VkComputePipelineCreateInfo-layout-parameter",
           "%s: pCreateInfos[%u].layout 0x%llx is not a live VkPipelineLayout", fn, i,
           (unsigned long long)rawHandle(ci.layout));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  char what[64];
  std::snprintf(what, sizeof what, "%s: pCreateInfos[%u].stage", fn, i);
  PreparedStage stage;
  if (!prepareStage(dev, ci.stage, spv::ExecutionModelGLCompute, what, &stage)) return VK_ERROR_VALIDATION_FAILED_EXT;
  CompiledStage compiled =
      compileStage(dev, stage, !(ci.flags & VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT), cache, fn, what);
  if (compiled.result != VK_SUCCESS) return compiled.result;
  const std::shared_ptr<const spirv::CompiledShader>& shader = compiled.shader;

  const VkPhysicalDeviceLimits& lim = dev->physicalDevice->properties10.limits;
  const uint32_t* ls = shader->localSize;
  static const char* const kSizeVuids[3] = {"VUID-RuntimeSpirv-x-06429", "VUID-RuntimeSpirv-y-06430",
                                            "VUID-RuntimeSpirv-z-06431"};
  for (int d = 0; d < 3; ++d) {
    // VUID-RuntimeSpirv-x-06429, VUID-RuntimeSpirv-y-06430, VUID-RuntimeSpirv-z-06431
    if (ls[d] > lim.maxComputeWorkGroupSize[d] || ls[d] == 0) {
      report(dev, Severity::Error, kSizeVuids[d],
             "%s: pCreateInfos[%u]: workgroup size %u in dimension %d is outside 1..%u", fn, i, ls[d], d,
             lim.maxComputeWorkGroupSize[d]);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-RuntimeSpirv-x-06432
  if (uint64_t(ls[0]) * ls[1] * ls[2] > lim.maxComputeWorkGroupInvocations) {
    report(dev, Severity::Error, "VUID-RuntimeSpirv-x-06432",
           "%s: pCreateInfos[%u]: workgroup size %ux%ux%u exceeds %u invocations", fn, i, ls[0], ls[1], ls[2],
           lim.maxComputeWorkGroupInvocations);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-RuntimeSpirv-Workgroup-06530
  if (shader->workgroupMemorySize > lim.maxComputeSharedMemorySize) {
    report(
        dev, Severity::Error, "VUID-RuntimeSpirv-Workgroup-06530",
        "%s: pCreateInfos[%u]: the shader uses %u bytes of workgroup memory, more than maxComputeSharedMemorySize (%u)",
        fn, i, shader->workgroupMemorySize, lim.maxComputeSharedMemorySize);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // Every resource the shader uses needs a binding of its type in the layout, visible to the compute stage.
  std::string detail;
  static const char* const kLayoutVuids[] = {nullptr, "VUID-VkComputePipelineCreateInfo-layout-07988",
                                             "VUID-VkComputePipelineCreateInfo-layout-07990",
                                             "VUID-VkComputePipelineCreateInfo-layout-07991"};
  // VUID-VkComputePipelineCreateInfo-layout-07988, -07990, -07991
  if (LayoutMismatch m = checkLayoutProvides(*layout, *shader, VK_SHADER_STAGE_COMPUTE_BIT, &detail);
      m != LayoutMismatch::None) {
    report(dev, Severity::Error, kLayoutVuids[int(m)], "%s: pCreateInfos[%u]: %s", fn, i, detail.c_str());
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* p = createObject<ComputePipeline>(alloc, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, ci.flags, layout, shader);
  if (!p) return VK_ERROR_OUT_OF_HOST_MEMORY;
  storeInCache(cache, stage.request, *shader);
  // Pipeline creation feedback (core in Vulkan 1.3): valid, with the time this pipeline took; the stage's from its
  // compilation (with the cache hit bit when the code came from the application's VkPipelineCache).
  if (auto* fb = findInChain<VkPipelineCreationFeedbackCreateInfo>(
          ci.pNext, VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO)) {
    uint64_t ns = uint64_t(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count());
    VkPipelineCreationFeedback f{compiled.feedback.flags, ns};
    if (fb->pPipelineCreationFeedback) *fb->pPipelineCreationFeedback = f;
    for (uint32_t s = 0; s < fb->pipelineStageCreationFeedbackCount && fb->pPipelineStageCreationFeedbacks; ++s)
      fb->pPipelineStageCreationFeedbacks[s] = f;
  }
  *out = toHandle(p);
  return VK_SUCCESS;
}

}  // namespace

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateComputePipelines(VkDevice device, VkPipelineCache pipelineCache,
                                                           uint32_t createInfoCount,
                                                           const VkComputePipelineCreateInfo* pCreateInfos,
                                                           const VkAllocationCallbacks* pAllocator,
                                                           VkPipeline* pPipelines) {
  static constexpr PipelineBatchCommand kCommand{"vkCreateComputePipelines",
                                                 "VUID-vkCreateComputePipelines-device-parameter",
                                                 "VUID-vkCreateComputePipelines-pipelineCache-parameter"};
  return createPipelineBatch(kCommand, device, pipelineCache, createInfoCount, pCreateInfos, pAllocator, pPipelines,
                             [&](Device* dev, PipelineCache* cache, uint32_t i, VkPipeline* out) {
                               return createOne(dev, cache, pCreateInfos[i], i, pAllocator, out);
                             });
}

}  // extern "C"
