// vkCreateRayTracingPipelinesKHR: validation (every rule about stages, groups, flags, libraries and
// capture/replay), then the build — SPIR-V analysis of each stage, group records from the device registry,
// library linking — run at once or, with a VkDeferredOperationKHR, on the threads that join it.
#include "rt/rt_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>

#include "exec/thread_pool.hpp"
#include "rt/library_link.hpp"
#include "rt/stack_size.hpp"
#include "runtime/alloc.hpp"
#include "runtime/deferred_operation.hpp"
#include "runtime/device.hpp"
#include "runtime/pipeline_cache.hpp"
#include "runtime/pipeline_layout.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_cache.hpp"
#include "runtime/shader_stage.hpp"
#include "spirv/module.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::rt {

RayTracingPipeline::RayTracingPipeline(Device* dev, VkPipelineCreateFlags flags, PipelineLayout* layout)
    : Pipeline(dev, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, flags, layout) {}

namespace {

constexpr VkShaderStageFlags kRtStages = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_ANY_HIT_BIT_KHR |
                                         VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR |
                                         VK_SHADER_STAGE_INTERSECTION_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR;
constexpr VkPipelineCreateFlags kFailOnCompile = VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT;
constexpr VkPipelineCreateFlags kEarlyReturn = VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT;

spv::ExecutionModel executionModelOf(VkShaderStageFlagBits stage) {
  switch (stage) {
    case VK_SHADER_STAGE_RAYGEN_BIT_KHR: return spv::ExecutionModelRayGenerationKHR;
    case VK_SHADER_STAGE_INTERSECTION_BIT_KHR: return spv::ExecutionModelIntersectionKHR;
    case VK_SHADER_STAGE_ANY_HIT_BIT_KHR: return spv::ExecutionModelAnyHitKHR;
    case VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR: return spv::ExecutionModelClosestHitKHR;
    case VK_SHADER_STAGE_MISS_BIT_KHR: return spv::ExecutionModelMissKHR;
    default: return spv::ExecutionModelCallableKHR;  // validate() admits only the six ray tracing stages
  }
}

bool stageIs(const VkRayTracingPipelineCreateInfoKHR& info, uint32_t index, VkShaderStageFlags allowed) {
  return index < info.stageCount && (info.pStages[index].stage & allowed) && info.pStages[index].stage != 0;
}

// One create info, prepared synchronously (everything copied out of the application's structures), built
// later (at once or on joining threads).
struct Job {
  uint32_t index = 0;
  bool nv = false;  // from vkCreateRayTracingPipelinesNV (translated: nvToKhr)
  const char* fn = "vkCreateRayTracingPipelinesKHR";
  VkPipelineCreateFlags flags = 0;
  PipelineLayout* layout = nullptr;
  LayoutShape layoutShape;
  uint32_t depth = 0;
  bool hasInterface = false;
  uint32_t maxPayload = 0, maxHitAttr = 0;
  bool dynamicStackSize = false;
  std::vector<std::shared_ptr<ShaderDesc>> stages;
  std::vector<PreparedStage> prepared;  // per stage: the checked code and compile request (runtime/shader_stage.hpp)
  // VkPipelineCreationFeedbackCreateInfo (core in Vulkan 1.3), written once the pipeline is built.
  const VkPipelineCreationFeedbackCreateInfo* feedback = nullptr;
  std::vector<VkPipelineCreationFeedback> stageFeedback;  // per stage, filled by compileStage
  std::vector<VkResult> stageResults;                     // per stage, filled by compileStage
  std::chrono::steady_clock::time_point start;            // when the command prepared the job
  struct Group {
    VkRayTracingShaderGroupTypeKHR type;
    uint32_t shader[4];
    bool hasCapture = false;
    bool zeroCapture = false;  // capture data of all zeros: taken as none (see below)
    uint8_t capture[kCaptureSize];
  };
  std::vector<Group> groups;
  std::vector<RayTracingPipeline*> libraries;
  PipelineCache* cache = nullptr;
  const VkAllocationCallbacks* allocator = nullptr;

  VkResult result = VK_SUCCESS;
  RayTracingPipeline* pipeline = nullptr;
};

// The VUID of the VK_NV_ray_tracing rule that a KHR rule checked on a translated NV create info stands for.
const char* nvVuid(const char* khr) {
  static const std::pair<const char*, const char*> kMap[] = {
      {"VUID-VkRayTracingPipelineCreateInfoKHR-layout-parameter",
       "VUID-VkRayTracingPipelineCreateInfoNV-layout-parameter"},
      {"VUID-vkCreateRayTracingPipelinesKHR-flags-03816", "VUID-vkCreateRayTracingPipelinesNV-flags-03816"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-pipelineCreationCacheControl-02905",
       "VUID-VkRayTracingPipelineCreateInfoNV-pipelineCreationCacheControl-02905"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-maxPipelineRayRecursionDepth-03589",
       "VUID-VkRayTracingPipelineCreateInfoNV-maxRecursionDepth-03457"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-flags-03421", "VUID-VkRayTracingPipelineCreateInfoNV-flags-03421"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-flags-03422", "VUID-VkRayTracingPipelineCreateInfoNV-flags-03422"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-flags-03424", "VUID-VkRayTracingPipelineCreateInfoNV-flags-03424"},
      {"VUID-vkCreateRayTracingPipelinesKHR-flags-03415", "VUID-vkCreateRayTracingPipelinesNV-flags-03415"},
      {"VUID-vkCreateRayTracingPipelinesKHR-flags-03416", "VUID-vkCreateRayTracingPipelinesNV-flags-03416"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-stage-06899", "VUID-VkRayTracingPipelineCreateInfoNV-stage-06898"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03474", "VUID-VkRayTracingShaderGroupCreateInfoNV-type-02413"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03475", "VUID-VkRayTracingShaderGroupCreateInfoNV-type-02414"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03476", "VUID-VkRayTracingShaderGroupCreateInfoNV-type-02415"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03477", "VUID-VkRayTracingShaderGroupCreateInfoNV-type-02416"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-type-parameter",
       "VUID-VkRayTracingShaderGroupCreateInfoNV-type-parameter"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-closestHitShader-03478",
       "VUID-VkRayTracingShaderGroupCreateInfoNV-closestHitShader-02417"},
      {"VUID-VkRayTracingShaderGroupCreateInfoKHR-anyHitShader-03479",
       "VUID-VkRayTracingShaderGroupCreateInfoNV-anyHitShader-02418"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-pipelineStageCreationFeedbackCount-06652",
       "VUID-VkRayTracingPipelineCreateInfoNV-pipelineStageCreationFeedbackCount-06651"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-stage-03425", "VUID-VkRayTracingPipelineCreateInfoNV-stage-06232"},
      {"VUID-VkRayTracingPipelineCreateInfoKHR-layout-03427", "VUID-VkRayTracingPipelineCreateInfoNV-layout-03427"},
  };
  if (!khr) return nullptr;
  for (const auto& [k, n] : kMap)
    if (std::strcmp(k, khr) == 0) return n;
  return khr;  // (the other KHR rules concern flags and structures an NV create info cannot carry: checked first)
}

// Validation of pCreateInfos[i]; reports the first violation. Fills the job's libraries.
bool validate(Device* dev, const VkRayTracingPipelineCreateInfoKHR& info, uint32_t i,
              const VkRayTracingPipelineCreateInfoKHR* all, Job& job) {
  auto fail = [&](const Object* about, const char* vuid, const char* fmt, auto... args) {
    if (!job.nv) {
      report(about ? about : dev, Severity::Error, vuid, fmt, args...);
    } else {
      // A translated VkRayTracingPipelineCreateInfoNV: the rule under its NV name, the message naming the NV command.
      std::string text(1024, '\0');
      text.resize(std::min<size_t>(size_t(std::max(std::snprintf(text.data(), text.size(), fmt, args...), 0)),
                                   text.size() - 1));
      const std::string khr = "vkCreateRayTracingPipelinesKHR";
      if (text.compare(0, khr.size(), khr) == 0) text.replace(0, khr.size(), job.fn);
      report(about ? about : dev, Severity::Error, nvVuid(vuid), "%s", text.c_str());
    }
    return false;
  };
  // VUID-VkRayTracingPipelineCreateInfoKHR-layout-parameter
  job.layout = fromHandle<PipelineLayout>(info.layout);
  if (!job.layout)
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-layout-parameter",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].layout 0x%llx is not a live VkPipelineLayout", i,
                (unsigned long long)rawHandle(info.layout));
  job.layoutShape = shapeOf(*job.layout);
  // VUID-vkCreateRayTracingPipelinesKHR-flags-03816
  if (info.flags & VK_PIPELINE_CREATE_DISPATCH_BASE_BIT)
    return fail(nullptr, "VUID-vkCreateRayTracingPipelinesKHR-flags-03816",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].flags 0x%x contains VK_PIPELINE_CREATE_DISPATCH_BASE",
                i, info.flags);
  // VUID-VkRayTracingPipelineCreateInfoKHR-pipelineCreationCacheControl-02905
  if ((info.flags & (kFailOnCompile | kEarlyReturn)) && !dev->enabled(Feature::pipelineCreationCacheControl))
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-pipelineCreationCacheControl-02905",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].flags 0x%x uses FAIL_ON_PIPELINE_COMPILE_REQUIRED or "
                "EARLY_RETURN_ON_FAILURE without the pipelineCreationCacheControl feature",
                i, info.flags);
  // VUID-VkRayTracingPipelineCreateInfoKHR-maxPipelineRayRecursionDepth-03589
  if (info.maxPipelineRayRecursionDepth > 31)
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-maxPipelineRayRecursionDepth-03589",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].maxPipelineRayRecursionDepth %u exceeds "
                "maxRayRecursionDepth 31",
                i, info.maxPipelineRayRecursionDepth);
  // VUID-VkRayTracingPipelineCreateInfoKHR-flags-06546
  const VkPipelineCreateFlags skipBoth =
      VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR | VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR;
  if ((info.flags & skipBoth) == skipBoth)
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-06546",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].flags has both SKIP_TRIANGLES and SKIP_AABBS", i);
  // VUID-VkRayTracingPipelineCreateInfoKHR-rayTraversalPrimitiveCulling-03596
  if ((info.flags & VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR) &&
      !dev->enabled(Feature::rayTraversalPrimitiveCulling))
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-rayTraversalPrimitiveCulling-03596",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has SKIP_AABBS without rayTraversalPrimitiveCulling",
                i);
  // VUID-VkRayTracingPipelineCreateInfoKHR-rayTraversalPrimitiveCulling-03597
  if ((info.flags & VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR) &&
      !dev->enabled(Feature::rayTraversalPrimitiveCulling))
    return fail(
        nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-rayTraversalPrimitiveCulling-03597",
        "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has SKIP_TRIANGLES without rayTraversalPrimitiveCulling", i);
  const bool captureFlag = info.flags & VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR;
  // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03598
  if (captureFlag && !dev->enabled(Feature::rayTracingPipelineShaderGroupHandleCaptureReplay))
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03598",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has SHADER_GROUP_HANDLE_CAPTURE_REPLAY but "
                "rayTracingPipelineShaderGroupHandleCaptureReplay is not enabled",
                i);
  // Derivatives.
  if (info.flags & VK_PIPELINE_CREATE_DERIVATIVE_BIT) {
    Pipeline* base = nullptr;
    if (info.basePipelineHandle != VK_NULL_HANDLE) {
      // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03424
      if (info.basePipelineIndex != -1)
        return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03424",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has basePipelineHandle and basePipelineIndex %d "
                    "(must be -1)",
                    i, info.basePipelineIndex);
      base = fromHandle<Pipeline>(info.basePipelineHandle);
      // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03421
      if (!asRayTracing(base))
        return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03421",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].basePipelineHandle 0x%llx is not a live ray "
                    "tracing pipeline",
                    i, (unsigned long long)rawHandle(info.basePipelineHandle));
      // VUID-vkCreateRayTracingPipelinesKHR-flags-03416
      if (!(base->createFlags & VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT))
        return fail(base, "VUID-vkCreateRayTracingPipelinesKHR-flags-03416",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u]'s base pipeline was created without "
                    "VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT",
                    i);
    } else {
      // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03422
      if (info.basePipelineIndex < 0)
        return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03422",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] is a derivative with neither basePipelineHandle "
                    "nor basePipelineIndex (%d)",
                    i, info.basePipelineIndex);
      // VUID-vkCreateRayTracingPipelinesKHR-flags-03415
      if (static_cast<uint32_t>(info.basePipelineIndex) >= i)
        return fail(nullptr, "VUID-vkCreateRayTracingPipelinesKHR-flags-03415",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].basePipelineIndex %d is not less than %u", i,
                    info.basePipelineIndex, i);
      // VUID-vkCreateRayTracingPipelinesKHR-flags-03416
      if (!(all[info.basePipelineIndex].flags & VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT))
        return fail(nullptr, "VUID-vkCreateRayTracingPipelinesKHR-flags-03416",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u]'s base pCreateInfos[%d] does not have "
                    "VK_PIPELINE_CREATE_ALLOW_DERIVATIVES_BIT",
                    i, info.basePipelineIndex);
    }
  } else if (info.basePipelineHandle != VK_NULL_HANDLE && info.basePipelineIndex != -1) {
    // VUID-VkRayTracingPipelineCreateInfoKHR-flags-03423 (only meaningful for derivatives; both set is wrong)
  }
  // Dynamic states. VUID-VkRayTracingPipelineCreateInfoKHR-pDynamicStates-03602
  if (info.pDynamicState) {
    for (uint32_t d = 0; d < info.pDynamicState->dynamicStateCount; ++d) {
      VkDynamicState s = info.pDynamicState->pDynamicStates[d];
      if (s != VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR)
        return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-pDynamicStates-03602",
                    "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pDynamicState->pDynamicStates[%u] is %d; only "
                    "VK_DYNAMIC_STATE_RAY_TRACING_PIPELINE_STACK_SIZE_KHR is allowed",
                    i, d, (int)s);
      job.dynamicStackSize = true;
    }
  }
  // Stages. VUID-VkRayTracingPipelineCreateInfoKHR-stage-06899
  for (uint32_t s = 0; s < info.stageCount; ++s) {
    VkShaderStageFlagBits st = info.pStages[s].stage;
    if (!(st & kRtStages) || (st & (st - 1)))
      return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-stage-06899",
                  "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pStages[%u].stage 0x%x is not a ray tracing stage",
                  i, s, (unsigned)st);
  }
  // Groups.
  const bool mixedOk = dev->enabled(Feature::rayTracingPipelineShaderGroupHandleCaptureReplayMixed);
  for (uint32_t g = 0; g < info.groupCount; ++g) {
    const VkRayTracingShaderGroupCreateInfoKHR& gr = info.pGroups[g];
    const char* vuid = nullptr;
    const char* what = nullptr;
    switch (gr.type) {
      case VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR:
        if (!stageIs(
                info, gr.generalShader,
                VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_MISS_BIT_KHR | VK_SHADER_STAGE_CALLABLE_BIT_KHR)) {
          vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03474";
          what = "generalShader is not the index of a raygen, miss or callable stage";
        } else if (gr.closestHitShader != VK_SHADER_UNUSED_KHR || gr.anyHitShader != VK_SHADER_UNUSED_KHR ||
                   gr.intersectionShader != VK_SHADER_UNUSED_KHR) {
          vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03475";
          what =
              "a GENERAL group has a closestHitShader, anyHitShader or intersectionShader that is not "
              "VK_SHADER_UNUSED_KHR";
        }
        break;
      case VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR:
        if (!stageIs(info, gr.intersectionShader, VK_SHADER_STAGE_INTERSECTION_BIT_KHR)) {
          vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03476";
          what = "intersectionShader of a PROCEDURAL_HIT_GROUP is not the index of an intersection stage";
        }
        break;
      case VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR:
        if (gr.intersectionShader != VK_SHADER_UNUSED_KHR) {
          vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-type-03477";
          what = "a TRIANGLES_HIT_GROUP has an intersectionShader";
        }
        break;
      default:
        vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-type-parameter";
        what = "type is not a VkRayTracingShaderGroupTypeKHR value";
        break;
    }
    if (!vuid && gr.type != VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR) {
      if (gr.closestHitShader != VK_SHADER_UNUSED_KHR &&
          !stageIs(info, gr.closestHitShader, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR)) {
        vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-closestHitShader-03478";
        what = "closestHitShader is neither VK_SHADER_UNUSED_KHR nor the index of a closest-hit stage";
      } else if (gr.anyHitShader != VK_SHADER_UNUSED_KHR &&
                 !stageIs(info, gr.anyHitShader, VK_SHADER_STAGE_ANY_HIT_BIT_KHR)) {
        vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-anyHitShader-03479";
        what = "anyHitShader is neither VK_SHADER_UNUSED_KHR nor the index of an any-hit stage";
      } else if ((info.flags & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR) &&
                 gr.anyHitShader == VK_SHADER_UNUSED_KHR) {
        vuid = "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03470";
        what = "NO_NULL_ANY_HIT_SHADERS is set but the hit group's anyHitShader is VK_SHADER_UNUSED_KHR";
      } else if ((info.flags & VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR) &&
                 gr.closestHitShader == VK_SHADER_UNUSED_KHR) {
        vuid = "VUID-VkRayTracingPipelineCreateInfoKHR-flags-03471";
        what = "NO_NULL_CLOSEST_HIT_SHADERS is set but the hit group's closestHitShader is VK_SHADER_UNUSED_KHR";
      }
    }
    if (!vuid && gr.pShaderGroupCaptureReplayHandle) {
      // VUID-VkRayTracingPipelineCreateInfoKHR-rayTracingPipelineShaderGroupHandleCaptureReplay-03599
      if (dev->enabled(Feature::rayTracingPipelineShaderGroupHandleCaptureReplay) && !captureFlag) {
        vuid = "VUID-VkRayTracingPipelineCreateInfoKHR-rayTracingPipelineShaderGroupHandleCaptureReplay-03599";
        what = "pShaderGroupCaptureReplayHandle is given but flags lack SHADER_GROUP_HANDLE_CAPTURE_REPLAY";
      } else if (captureFlag && !mixedOk && registryOf(dev).anyNonReplayed()) {
        // VUID-VkRayTracingShaderGroupCreateInfoKHR-rayTracingPipelineShaderGroupHandleCaptureReplayMixed-03603
        vuid = "VUID-VkRayTracingShaderGroupCreateInfoKHR-rayTracingPipelineShaderGroupHandleCaptureReplayMixed-03603";
        what =
            "capture data is given after groups without it were created, and "
            "rayTracingPipelineShaderGroupHandleCaptureReplayMixed is not enabled";
      }
    }
    if (vuid)
      return fail(nullptr, vuid,
                  "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pGroups[%u] (type %d, general %u, closestHit %u, "
                  "anyHit %u, intersection %u; stageCount %u): %s",
                  i, g, (int)gr.type, gr.generalShader, gr.closestHitShader, gr.anyHitShader, gr.intersectionShader,
                  info.stageCount, what);
  }
  // VUID-VkRayTracingPipelineCreateInfoKHR-pipelineStageCreationFeedbackCount-06652
  job.feedback = findInChain<VkPipelineCreationFeedbackCreateInfo>(
      info.pNext, VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO);
  if (job.feedback && job.feedback->pipelineStageCreationFeedbackCount != 0 &&
      job.feedback->pipelineStageCreationFeedbackCount != info.stageCount)
    return fail(nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-pipelineStageCreationFeedbackCount-06652",
                "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u]: VkPipelineCreationFeedbackCreateInfo::"
                "pipelineStageCreationFeedbackCount %u is neither 0 nor stageCount %u",
                i, job.feedback->pipelineStageCreationFeedbackCount, info.stageCount);
  if (!checkLibraries(dev, info, i, job.layoutShape, job.libraries)) return false;
  // VUID-VkRayTracingPipelineCreateInfoKHR-stage-03425
  if (!(info.flags & VK_PIPELINE_CREATE_LIBRARY_BIT_KHR)) {
    bool raygen = false;
    for (uint32_t s = 0; s < info.stageCount; ++s) raygen |= info.pStages[s].stage == VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    for (RayTracingPipeline* l : job.libraries)
      for (const GroupRecord* r : l->groups)
        raygen |= r->desc.shaders[kGeneral] && r->desc.shaders[kGeneral]->stage == VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    if (!raygen)
      return fail(
          nullptr, "VUID-VkRayTracingPipelineCreateInfoKHR-stage-03425",
          "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] is not a library and has no raygen stage (%u stages, "
          "%zu libraries)",
          i, info.stageCount, job.libraries.size());
  }
  return true;
}

// Copies what the build needs out of the create info (code resolved, specialization canonicalized).
bool prepare(Device* dev, const VkRayTracingPipelineCreateInfoKHR& info, uint32_t i, Job& job) {
  job.index = i;
  job.flags = info.flags;
  job.depth = info.maxPipelineRayRecursionDepth;
  if (info.pLibraryInterface) {
    job.hasInterface = true;
    job.maxPayload = info.pLibraryInterface->maxPipelineRayPayloadSize;
    job.maxHitAttr = info.pLibraryInterface->maxPipelineRayHitAttributeSize;
  }
  for (uint32_t s = 0; s < info.stageCount; ++s) {
    const VkPipelineShaderStageCreateInfo& st = info.pStages[s];
    char what[96];
    std::snprintf(what, sizeof(what), "%s: pCreateInfos[%u].pStages[%u]", job.fn, i, s);
    PreparedStage ps;
    if (!prepareStage(dev, st, executionModelOf(st.stage), what, &ps)) return false;
    auto d = std::make_shared<ShaderDesc>();
    d->codeHash = ps.codeHash;
    d->code = ps.code;
    if (ps.code) hitBuiltinsRead(*ps.code, &d->readsTransforms, &d->readsPositions);
    d->entry = st.pName;
    d->stage = st.stage;
    d->flags = st.flags;
    // The group's content names the specialization checked and sorted by prepareStage.
    for (const spirv::SpecValue& v : ps.request.specialization)
      d->specialization.emplace_back(v.specId, std::string(v.bytes.begin(), v.bytes.end()));
    job.stages.push_back(std::move(d));
    job.prepared.push_back(std::move(ps));
  }
  // Combined counter adds (abi::PendingAdds): where any stage has an add that may be combined, every stage is
  // compiled to check its accesses against the pending word; a pipeline without one pays nothing for it.
  const bool adds = std::any_of(job.prepared.begin(), job.prepared.end(), [](const PreparedStage& ps) {
    return ps.code && spirv::hasCombinableAdds(ps.code->data(), ps.code->size());
  });
  if (adds) {
    for (PreparedStage& ps : job.prepared) {
      ps.request.combineAdds = true;
      ps.key = shaderKey(ps.codeHash, ps.request);
    }
  }
  for (uint32_t g = 0; g < info.groupCount; ++g) {
    const VkRayTracingShaderGroupCreateInfoKHR& gr = info.pGroups[g];
    Job::Group jg{gr.type, {gr.generalShader, gr.closestHitShader, gr.anyHitShader, gr.intersectionShader}};
    if (gr.type != VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR) jg.shader[kGeneral] = VK_SHADER_UNUSED_KHR;
    if ((info.flags & VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR) &&
        gr.pShaderGroupCaptureReplayHandle) {
      std::memcpy(jg.capture, gr.pShaderGroupCaptureReplayHandle, kCaptureSize);
      jg.hasCapture = std::any_of(jg.capture, jg.capture + kCaptureSize, [](uint8_t b) { return b != 0; });
      jg.zeroCapture = !jg.hasCapture;
    }
    job.groups.push_back(jg);
  }
  return true;
}

// The compiled code of stage `s`, shared through the device (runtime/shader_cache.hpp): compiled, found live, or
// loaded from the job's VkPipelineCache. Writes only the stage's own slots, so that the stages of a job compile
// concurrently.
void compileStage(Device* dev, Job& job, size_t s) {
  ShaderDesc& d = *job.stages[s];
  char what[96];
  std::snprintf(what, sizeof(what), "%s: pCreateInfos[%u].pStages[%zu]", job.fn, job.index, s);
  CompiledStage c = vkrt::compileStage(dev, job.prepared[s], !(job.flags & kFailOnCompile), job.cache, job.fn, what);
  job.stageFeedback[s] = c.feedback;
  job.stageResults[s] = c.result;
  d.compiled = c.shader;
}

// Every stage of the job, on the thread pool's threads and the calling one (a pipeline of 16 stages compiles in
// about the time of its slowest shader when the pool has 16 threads).
void compileStages(Job& job, Device* dev) {
  exec::ThreadPool::instance().runConcurrently(job.stages.size(), [&](uint64_t s) { compileStage(dev, job, s); });
}

// The rest of the build once every stage was compiled (compileStage): the layout and interface checks, group
// records, linking. Runs on the calling thread or on the thread that ends the deferred operation.
void assemble(Device* dev, Job& job) {
  // The first stage that could not be had decides the result (the order of the create info, not of completion).
  for (VkResult r : job.stageResults) {
    if (r != VK_SUCCESS) {
      job.result = r;
      return;
    }
  }
  // VUID-VkRayTracingPipelineCreateInfoKHR-layout-03427: the layout provides every resource of every stage.
  for (size_t s = 0; s < job.stages.size(); ++s) {
    const ShaderDesc& d = *job.stages[s];
    std::string detail;
    if (checkLayoutProvides(*job.layout, *d.compiled, d.stage, &detail) != LayoutMismatch::None) {
      report(dev, Severity::Error,
             job.nv ? "VUID-VkRayTracingPipelineCreateInfoNV-layout-03427"
                    : "VUID-VkRayTracingPipelineCreateInfoKHR-layout-03427",
             "%s: pCreateInfos[%u].pStages[%zu] (stage 0x%x, \"%s\"): %s", job.fn, job.index, s, (unsigned)d.stage,
             d.entry.c_str(), detail.c_str());
      job.result = VK_ERROR_VALIDATION_FAILED_EXT;
      return;
    }
  }
  // The pipeline interface: VkRayTracingPipelineInterfaceCreateInfoKHR defines maxPipelineRayPayloadSize and
  // maxPipelineRayHitAttributeSize as the largest payload / hit attribute block any shader of the pipeline
  // declares. The specification gives this rule no VUID (1.3.239); a shader that declares more than the
  // interface admits is reported without one. (Libraries' shaders were checked against the library's interface,
  // which VUID-VkRayTracingPipelineCreateInfoKHR-pLibraryInfo-03593 makes equal to this one.)
  if (job.hasInterface) {
    for (size_t s = 0; s < job.stages.size(); ++s) {
      const ShaderDesc& d = *job.stages[s];
      const char *what = nullptr, *member = nullptr;
      uint32_t declared = 0, limit = 0;
      const spirv::RayStageInfo& ray = d.compiled->ray;
      if (ray.payloadBytes > job.maxPayload) {
        what = "a ray payload";
        member = "maxPipelineRayPayloadSize";
        declared = ray.payloadBytes;
        limit = job.maxPayload;
      } else if (ray.hitAttributeBytes > job.maxHitAttr) {
        what = "a hit attribute";
        member = "maxPipelineRayHitAttributeSize";
        declared = ray.hitAttributeBytes;
        limit = job.maxHitAttr;
      }
      if (what) {
        report(dev, Severity::Error, nullptr,
               "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pStages[%zu] (stage 0x%x, \"%s\") declares %s of "
               "%u bytes, more than pLibraryInterface->%s %u (the largest any shader of the pipeline uses)",
               job.index, s, (unsigned)d.stage, d.entry.c_str(), what, declared, member, limit);
        job.result = VK_ERROR_VALIDATION_FAILED_EXT;
        return;
      }
    }
  }
  auto* p =
      createObject<RayTracingPipeline>(job.allocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, job.flags, job.layout);
  if (!p) {
    job.result = VK_ERROR_OUT_OF_HOST_MEMORY;
    return;
  }
  p->maxRecursionDepth = job.depth;
  if (job.nv && (job.flags & VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV))
    p->deferredStages.assign(job.stages.size(), 1);  // each waits for its vkCompileDeferredNV
  p->hasInterface = job.hasInterface;
  p->maxPayloadSize = job.maxPayload;
  p->maxHitAttributeSize = job.maxHitAttr;
  p->dynamicStackSize = job.dynamicStackSize;
  p->layoutShape = job.layoutShape;
  GroupRegistry& reg = registryOf(dev);
  for (size_t g = 0; g < job.groups.size(); ++g) {
    const Job::Group& jg = job.groups[g];
    GroupDesc desc;
    desc.type = jg.type;
    for (int k = 0; k < 4; ++k)
      if (jg.shader[k] != VK_SHADER_UNUSED_KHR) desc.shaders[k] = job.stages[jg.shader[k]];
    const GroupRecord* r = nullptr;
    if (jg.hasCapture) {
      ReplayError e;
      r = reg.replay(desc, jg.capture, &e, p->handleValue());
      if (!r) {
        report(dev, Severity::Error, nullptr,
               "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pGroups[%zu].pShaderGroupCaptureReplayHandle is "
               "refused: %s",
               job.index, g, e.reason.c_str());
        destroyObject(p, job.allocator);
        job.result = VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS;
        return;
      }
    } else if (jg.zeroCapture) {
      // Capture data of all zeros is not data vkrt wrote (it carries a non-zero handle and magic words), and the
      // specification asks nothing of its content: vkrt takes it as no capture data. A tool that records capture
      // data it could not query (GFXReconstruct 0.9.18 records zeros for a library whose query failed) then replays;
      // handles are content-derived, so the group gets the handle it had when captured on vkrt. For the
      // CaptureReplayMixed rule (VUID-...-03603) the group counts as one given capture data, as the application did.
      report(dev, Severity::Info, nullptr,
             "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u].pGroups[%zu].pShaderGroupCaptureReplayHandle points at "
             "64 zero bytes, which is no capture data vkrt wrote; taken as none: the group gets its content-derived "
             "handle (the one it had when captured on vkrt)",
             job.index, g);
      r = reg.acquire(desc, dev, p->handleValue(), true);
    } else {
      r = reg.acquire(desc, dev, p->handleValue());
    }
    p->groups.push_back(r);
  }
  p->ownGroupCount = static_cast<uint32_t>(p->groups.size());
  linkLibraries(job.libraries, p->groups);
  p->defaultStackSize = defaultPipelineStackSize(p->groups, job.depth);
  for (size_t s = 0; s < job.stages.size(); ++s)
    storeInCache(job.cache, job.prepared[s].request, *job.stages[s]->compiled);
  if (job.feedback) {
    // The pipeline hit the application's cache when every stage did (a pipeline of libraries only has none).
    bool allHit = !job.stageFeedback.empty();
    for (const VkPipelineCreationFeedback& f : job.stageFeedback)
      allHit &= (f.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT) != 0;
    const auto ns =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - job.start).count();
    if (job.feedback->pPipelineCreationFeedback)
      *job.feedback->pPipelineCreationFeedback = {
          VkPipelineCreationFeedbackFlags(
              VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT |
              (allHit ? VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT : 0)),
          uint64_t(ns)};
    for (uint32_t s = 0;
         s < job.feedback->pipelineStageCreationFeedbackCount && job.feedback->pPipelineStageCreationFeedbacks; ++s)
      job.feedback->pPipelineStageCreationFeedbacks[s] = job.stageFeedback[s];
  }
  job.pipeline = p;
}

// Writes pPipelines and returns the command's result once every job ran.
VkResult finish(std::vector<Job>& jobs, VkPipeline* out) {
  VkResult firstError = VK_SUCCESS;
  bool compileRequired = false;
  for (Job& j : jobs) {
    if (j.result == VK_PIPELINE_COMPILE_REQUIRED)
      compileRequired = true;
    else if (j.result != VK_SUCCESS && firstError == VK_SUCCESS)
      firstError = j.result;
  }
  if (firstError != VK_SUCCESS) {
    // Any error other than COMPILE_REQUIRED: nothing is created.
    for (Job& j : jobs) {
      if (j.pipeline) destroyObject(static_cast<Pipeline*>(j.pipeline), j.allocator);
      out[j.index] = VK_NULL_HANDLE;
    }
    return firstError;
  }
  bool stop = false;
  for (Job& j : jobs) {
    if (stop && j.pipeline) {
      destroyObject(static_cast<Pipeline*>(j.pipeline), j.allocator);
      j.pipeline = nullptr;
    }
    out[j.index] = j.pipeline ? toHandle(static_cast<Pipeline*>(j.pipeline)) : VK_NULL_HANDLE;
    if (j.result == VK_PIPELINE_COMPILE_REQUIRED && (j.flags & kEarlyReturn)) stop = true;
  }
  return compileRequired ? VK_PIPELINE_COMPILE_REQUIRED : VK_SUCCESS;
}

}  // namespace
}  // namespace vkrt::rt

namespace vkrt::rt {
namespace {

// The creation shared by vkCreateRayTracingPipelinesKHR and (through translated create infos)
// vkCreateRayTracingPipelinesNV, from the pipeline cache check on.
VkResult createPipelines(Device* dev, DeferredOperation* op, VkPipelineCache pipelineCache, uint32_t createInfoCount,
                         const VkRayTracingPipelineCreateInfoKHR* pCreateInfos, const VkAllocationCallbacks* pAllocator,
                         VkPipeline* pPipelines, const char* fn) {
  const bool nv = std::strcmp(fn, "vkCreateRayTracingPipelinesNV") == 0;
  PipelineCache* cache = nullptr;
  if (pipelineCache != VK_NULL_HANDLE) {
    cache = fromHandle<PipelineCache>(pipelineCache);
    // VUID-vkCreateRayTracingPipelinesKHR-pipelineCache-parameter,
    // VUID-vkCreateRayTracingPipelinesNV-pipelineCache-parameter
    if (!cache) {
      report(dev, Severity::Error,
             nv ? "VUID-vkCreateRayTracingPipelinesNV-pipelineCache-parameter"
                : "VUID-vkCreateRayTracingPipelinesKHR-pipelineCache-parameter",
             "%s: pipelineCache 0x%llx is not a live VkPipelineCache", fn,
             (unsigned long long)rawHandle(pipelineCache));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  auto jobs = std::make_shared<std::vector<Job>>(createInfoCount);
  for (uint32_t i = 0; i < createInfoCount; ++i) {
    Job& j = (*jobs)[i];
    j.cache = cache;
    j.allocator = pAllocator;
    j.nv = nv;
    j.fn = fn;
    if (!validate(dev, pCreateInfos[i], i, pCreateInfos, j) || !prepare(dev, pCreateInfos[i], i, j))
      return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (Job& j : *jobs) {
    j.stageFeedback.assign(j.stages.size(), VkPipelineCreationFeedback{});
    j.stageResults.assign(j.stages.size(), VK_SUCCESS);
    j.start = std::chrono::steady_clock::now();
  }
  if (!op) {
    for (Job& j : *jobs) {
      compileStages(j, dev);
      assemble(dev, j);
      // VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT: the later pipelines are not created (not even built, so
      // they leave no entries in the cache). finish() writes VK_NULL_HANDLE for them.
      if (j.result == VK_PIPELINE_COMPILE_REQUIRED && (j.flags & kEarlyReturn)) break;
    }
    return finish(*jobs, pPipelines);
  }
  // Deferred: each stage of each pipeline is a task for the threads that join the operation (as many can work as
  // there are stages); the thread that ends the last one assembles the pipelines and writes pPipelines.
  std::vector<std::function<void()>> tasks;
  for (uint32_t i = 0; i < createInfoCount; ++i)
    for (size_t s = 0; s < (*jobs)[i].stages.size(); ++s)
      tasks.push_back([dev, jobs, i, s] { compileStage(dev, (*jobs)[i], s); });
  op->start(std::move(tasks), [dev, jobs, pPipelines] {
    for (Job& j : *jobs) assemble(dev, j);
    return finish(*jobs, pPipelines);
  });
  return VK_OPERATION_DEFERRED_KHR;
}

}  // namespace
}  // namespace vkrt::rt

using namespace vkrt;
using namespace vkrt::rt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateRayTracingPipelinesKHR(
    VkDevice device, VkDeferredOperationKHR deferredOperation, VkPipelineCache pipelineCache, uint32_t createInfoCount,
    const VkRayTracingPipelineCreateInfoKHR* pCreateInfos, const VkAllocationCallbacks* pAllocator,
    VkPipeline* pPipelines) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkCreateRayTracingPipelinesKHR-rayTracingPipeline-03586
  if (!dev->enabled(Feature::rayTracingPipeline)) {
    report(dev, Severity::Error, "VUID-vkCreateRayTracingPipelinesKHR-rayTracingPipeline-03586",
           "vkCreateRayTracingPipelinesKHR: the rayTracingPipeline feature is not enabled");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  DeferredOperation* op = nullptr;
  if (deferredOperation != VK_NULL_HANDLE) {
    op = fromHandle<DeferredOperation>(deferredOperation);
    // VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03677
    if (!op) {
      report(dev, Severity::Error, "VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03677",
             "vkCreateRayTracingPipelinesKHR: deferredOperation 0x%llx is not a live VkDeferredOperationKHR",
             (unsigned long long)rawHandle(deferredOperation));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03678
    if (!op->complete()) {
      report(op, Severity::Error, "VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03678",
             "vkCreateRayTracingPipelinesKHR: deferredOperation is still running a previous operation");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    for (uint32_t i = 0; i < createInfoCount; ++i) {
      // VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03587
      if (pCreateInfos[i].flags & VK_PIPELINE_CREATE_EARLY_RETURN_ON_FAILURE_BIT) {
        report(op, Severity::Error, "VUID-vkCreateRayTracingPipelinesKHR-deferredOperation-03587",
               "vkCreateRayTracingPipelinesKHR: pCreateInfos[%u] has EARLY_RETURN_ON_FAILURE with a deferred operation",
               i);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
  }
  return createPipelines(dev, op, pipelineCache, createInfoCount, pCreateInfos, pAllocator, pPipelines,
                         "vkCreateRayTracingPipelinesKHR");
}

// vkCreateRayTracingPipelinesNV: the rules only the NV form has, then each create info translated into the KHR one
// (same stages, groups with no capture data, maxRecursionDepth as maxPipelineRayRecursionDepth) and created by the
// KHR path, so that groups, handles, stack sizes and every shared rule are the KHR path's (reported under the NV
// VUIDs: nvVuid).
VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateRayTracingPipelinesNV(VkDevice device, VkPipelineCache pipelineCache,
                                                                uint32_t createInfoCount,
                                                                const VkRayTracingPipelineCreateInfoNV* pCreateInfos,
                                                                const VkAllocationCallbacks* pAllocator,
                                                                VkPipeline* pPipelines) {
  const char* fn = "vkCreateRayTracingPipelinesNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  for (uint32_t i = 0; i < createInfoCount; ++i) pPipelines[i] = VK_NULL_HANDLE;
  struct Forbidden {
    VkPipelineCreateFlags flag;
    const char* vuid;
    const char* name;
  };
  // VUID-VkRayTracingPipelineCreateInfoNV-flags-02904, -03456, -03458, -03459, -03460, -03461, -03462, -03463,
  // -03588, -04948, -07402: flags of other pipeline kinds and of the KHR extension.
  static const Forbidden kForbidden[] = {
      {VK_PIPELINE_CREATE_INDIRECT_BINDABLE_BIT_NV, "VUID-VkRayTracingPipelineCreateInfoNV-flags-02904",
       "VK_PIPELINE_CREATE_INDIRECT_BINDABLE_BIT_NV"},
      {VK_PIPELINE_CREATE_LIBRARY_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoNV-flags-03456",
       "VK_PIPELINE_CREATE_LIBRARY_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR,
       "VUID-VkRayTracingPipelineCreateInfoNV-flags-03458",
       "VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_ANY_HIT_SHADERS_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR,
       "VUID-VkRayTracingPipelineCreateInfoNV-flags-03459",
       "VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_CLOSEST_HIT_SHADERS_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoNV-flags-03460",
       "VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_MISS_SHADERS_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_INTERSECTION_SHADERS_BIT_KHR,
       "VUID-VkRayTracingPipelineCreateInfoNV-flags-03461",
       "VK_PIPELINE_CREATE_RAY_TRACING_NO_NULL_INTERSECTION_SHADERS_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoNV-flags-03462",
       "VK_PIPELINE_CREATE_RAY_TRACING_SKIP_AABBS_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR, "VUID-VkRayTracingPipelineCreateInfoNV-flags-03463",
       "VK_PIPELINE_CREATE_RAY_TRACING_SKIP_TRIANGLES_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR,
       "VUID-VkRayTracingPipelineCreateInfoNV-flags-03588",
       "VK_PIPELINE_CREATE_RAY_TRACING_SHADER_GROUP_HANDLE_CAPTURE_REPLAY_BIT_KHR"},
      {VK_PIPELINE_CREATE_RAY_TRACING_ALLOW_MOTION_BIT_NV, "VUID-VkRayTracingPipelineCreateInfoNV-flags-04948",
       "VK_PIPELINE_CREATE_RAY_TRACING_ALLOW_MOTION_BIT_NV"},
      {VK_PIPELINE_CREATE_RAY_TRACING_OPACITY_MICROMAP_BIT_EXT, "VUID-VkRayTracingPipelineCreateInfoNV-flags-07402",
       "VK_PIPELINE_CREATE_RAY_TRACING_OPACITY_MICROMAP_BIT_EXT"},
  };
  std::vector<VkRayTracingPipelineCreateInfoKHR> infos(createInfoCount);
  std::vector<std::vector<VkRayTracingShaderGroupCreateInfoKHR>> groups(createInfoCount);
  for (uint32_t i = 0; i < createInfoCount; ++i) {
    const VkRayTracingPipelineCreateInfoNV& n = pCreateInfos[i];
    for (const Forbidden& f : kForbidden) {
      if (n.flags & f.flag) {
        report(dev, Severity::Error, f.vuid, "%s: pCreateInfos[%u].flags 0x%x contains %s", fn, i, n.flags, f.name);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    // VUID-VkRayTracingPipelineCreateInfoNV-flags-02957
    if ((n.flags & VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV) && (n.flags & kFailOnCompile)) {
      report(dev, Severity::Error, "VUID-VkRayTracingPipelineCreateInfoNV-flags-02957",
             "%s: pCreateInfos[%u].flags 0x%x has both VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV and "
             "VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT",
             fn, i, n.flags);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    for (uint32_t g = 0; g < n.groupCount; ++g) {
      const VkRayTracingShaderGroupCreateInfoNV& ng = n.pGroups[g];
      VkRayTracingShaderGroupCreateInfoKHR k{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
      k.type = ng.type;
      k.generalShader = ng.generalShader;
      k.closestHitShader = ng.closestHitShader;
      k.anyHitShader = ng.anyHitShader;
      k.intersectionShader = ng.intersectionShader;
      groups[i].push_back(k);
    }
    VkRayTracingPipelineCreateInfoKHR& k = infos[i];
    k = {VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    k.pNext = n.pNext;  // VkPipelineCreationFeedbackCreateInfo is what it may hold
    k.flags = n.flags;
    k.stageCount = n.stageCount;
    k.pStages = n.pStages;
    k.groupCount = n.groupCount;
    k.pGroups = groups[i].data();
    k.maxPipelineRayRecursionDepth = n.maxRecursionDepth;
    k.layout = n.layout;
    k.basePipelineHandle = n.basePipelineHandle;
    k.basePipelineIndex = n.basePipelineIndex;
  }
  return createPipelines(dev, nullptr, pipelineCache, createInfoCount, infos.data(), pAllocator, pPipelines, fn);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CompileDeferredNV(VkDevice device, VkPipeline pipeline, uint32_t shader) {
  const char* fn = "vkCompileDeferredNV";
  Device* dev = fromHandleUnchecked<Device>(device);
  RayTracingPipeline* p = asRayTracing(fromHandle<Pipeline>(pipeline));
  // VUID-vkCompileDeferredNV-pipeline-04621
  if (!p) {
    report(dev, Severity::Error, "VUID-vkCompileDeferredNV-pipeline-04621",
           "%s: pipeline 0x%llx is not a live ray tracing pipeline", fn, (unsigned long long)rawHandle(pipeline));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkCompileDeferredNV-pipeline-02237
  if (!(p->createFlags & VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV)) {
    report(p, Severity::Error, "VUID-vkCompileDeferredNV-pipeline-02237",
           "%s: the pipeline was not created with VK_PIPELINE_CREATE_DEFER_COMPILE_BIT_NV", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::lock_guard lock(p->deferredMutex);
  // (The specification names no VUID for a shader index outside pStages.)
  if (shader >= p->deferredStages.size()) {
    report(p, Severity::Error, nullptr, "%s: shader %u is not an index into the pipeline's %zu stages", fn, shader,
           p->deferredStages.size());
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkCompileDeferredNV-shader-02238
  if (!p->deferredStages[shader]) {
    report(p, Severity::Error, "VUID-vkCompileDeferredNV-shader-02238",
           "%s: shader %u was already compiled by an earlier vkCompileDeferredNV", fn, shader);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  p->deferredStages[shader] = 0;
  return VK_SUCCESS;
}

}  // extern "C"
