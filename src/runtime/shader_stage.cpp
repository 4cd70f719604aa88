#include "runtime/shader_stage.hpp"

#include <algorithm>
#include <chrono>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_module.hpp"
#include "spirv/module.hpp"

namespace vkrt {

namespace {

const char* modelName(spv::ExecutionModel m) {
  switch (m) {
    case spv::ExecutionModelGLCompute: return "GLCompute";
    case spv::ExecutionModelVertex: return "Vertex";
    case spv::ExecutionModelFragment: return "Fragment";
    case spv::ExecutionModelRayGenerationKHR: return "RayGenerationKHR";
    case spv::ExecutionModelIntersectionKHR: return "IntersectionKHR";
    case spv::ExecutionModelAnyHitKHR: return "AnyHitKHR";
    case spv::ExecutionModelClosestHitKHR: return "ClosestHitKHR";
    case spv::ExecutionModelMissKHR: return "MissKHR";
    default: return "CallableKHR";
  }
}

// The VkSpecializationInfo rules; fills the request's specialization sorted by constant id.
bool specialization(const Object* about, const VkSpecializationInfo* si, const char* what,
                    std::vector<spirv::SpecValue>* out) {
  if (!si) return true;
  // VUID-VkSpecializationInfo-pMapEntries-parameter, VUID-VkSpecializationInfo-pData-parameter
  if ((si->mapEntryCount && !si->pMapEntries) || (si->dataSize && !si->pData)) {
    report(about, Severity::Error,
           si->mapEntryCount && !si->pMapEntries ? "VUID-VkSpecializationInfo-pMapEntries-parameter"
                                                 : "VUID-VkSpecializationInfo-pData-parameter",
           "%s.pSpecializationInfo: mapEntryCount %u with pMapEntries %p, dataSize %zu with pData %p", what,
           si->mapEntryCount, static_cast<const void*>(si->pMapEntries), si->dataSize, si->pData);
    return false;
  }
  for (uint32_t e = 0; e < si->mapEntryCount; ++e) {
    const VkSpecializationMapEntry& me = si->pMapEntries[e];
    // VUID-VkSpecializationInfo-offset-00773
    if (me.offset >= si->dataSize) {
      report(about, Severity::Error, "VUID-VkSpecializationInfo-offset-00773",
             "%s.pSpecializationInfo->pMapEntries[%u].offset (%u) is not less than dataSize (%zu)", what, e, me.offset,
             si->dataSize);
      return false;
    }
    // VUID-VkSpecializationInfo-pMapEntries-00774
    if (me.size > si->dataSize - me.offset) {
      report(about, Severity::Error, "VUID-VkSpecializationInfo-pMapEntries-00774",
             "%s.pSpecializationInfo->pMapEntries[%u].size (%zu) exceeds dataSize (%zu) minus offset (%u)", what, e,
             me.size, si->dataSize, me.offset);
      return false;
    }
    // VUID-VkSpecializationInfo-constantID-04911
    for (uint32_t k = 0; k < e; ++k) {
      if (si->pMapEntries[k].constantID == me.constantID) {
        report(about, Severity::Error, "VUID-VkSpecializationInfo-constantID-04911",
               "%s.pSpecializationInfo->pMapEntries[%u] and [%u] both specialize constant %u", what, k, e,
               me.constantID);
        return false;
      }
    }
    const uint8_t* bytes = static_cast<const uint8_t*>(si->pData) + me.offset;
    out->push_back({me.constantID, std::vector<uint8_t>(bytes, bytes + me.size)});
  }
  std::stable_sort(out->begin(), out->end(),
                   [](const spirv::SpecValue& a, const spirv::SpecValue& b) { return a.specId < b.specId; });
  return true;
}

}  // namespace

// Subgroup size control (Vulkan 1.3, VK_EXT_subgroup_size_control). vkrt's subgroups have one invocation
// (minSubgroupSize = maxSubgroupSize = 1), so a size the application requires can only be 1, a varying size is 1,
// and every subgroup is full: the shader runs as it would anyway, and what is left to do is the rules. (The size
// rules on the workgroup hold for every valid workgroup: 02756's bound, 1 x maxComputeWorkgroupSubgroups, is
// maxComputeWorkGroupInvocations; 02757, 02758 and 02759 ask for multiples of 1.)
static bool checkSubgroupSize(const Object* about, const VkPipelineShaderStageCreateInfo& stage, const char* what) {
  const Device* dev = about->objectType == VK_OBJECT_TYPE_DEVICE ? static_cast<const Device*>(about) : about->device;
  const VkPhysicalDeviceVulkan13Properties& p13 = dev->physicalDevice->properties13;
  // VUID-VkPipelineShaderStageCreateInfo-flags-02784
  if ((stage.flags & VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT) &&
      !dev->enabled(Feature::subgroupSizeControl)) {
    report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-flags-02784",
           "%s.flags 0x%x has VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT, but the "
           "subgroupSizeControl feature is not enabled",
           what, stage.flags);
    return false;
  }
  // VUID-VkPipelineShaderStageCreateInfo-flags-02785
  if ((stage.flags & VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT) &&
      !dev->enabled(Feature::computeFullSubgroups)) {
    report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-flags-02785",
           "%s.flags 0x%x has VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT, but the "
           "computeFullSubgroups feature is not enabled",
           what, stage.flags);
    return false;
  }
  auto* required = findInChain<VkPipelineShaderStageRequiredSubgroupSizeCreateInfo>(
      stage.pNext, VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_REQUIRED_SUBGROUP_SIZE_CREATE_INFO);
  if (!required) return true;
  const uint32_t size = required->requiredSubgroupSize;
  // VUID-VkPipelineShaderStageCreateInfo-pNext-02755, -02754; VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-
  // requiredSubgroupSize-02760 / 02761 / 02762
  const char* vuid = !dev->enabled(Feature::subgroupSizeControl) || !(stage.stage & p13.requiredSubgroupSizeStages)
                         ? "VUID-VkPipelineShaderStageCreateInfo-pNext-02755"
                     : (stage.flags & VK_PIPELINE_SHADER_STAGE_CREATE_ALLOW_VARYING_SUBGROUP_SIZE_BIT)
                         ? "VUID-VkPipelineShaderStageCreateInfo-pNext-02754"
                     : size == 0 || (size & (size - 1))
                         ? "VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-requiredSubgroupSize-02760"
                     : size < p13.minSubgroupSize
                         ? "VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-requiredSubgroupSize-02761"
                     : size > p13.maxSubgroupSize
                         ? "VUID-VkPipelineShaderStageRequiredSubgroupSizeCreateInfo-requiredSubgroupSize-02762"
                         : nullptr;
  if (vuid) {
    report(about, Severity::Error, vuid,
           "%s: VkPipelineShaderStageRequiredSubgroupSizeCreateInfo::requiredSubgroupSize %u for stage 0x%x (flags "
           "0x%x; subgroupSizeControl %s; sizes %u-%u, a power of two; stages 0x%x)",
           what, size, stage.stage, stage.flags, dev->enabled(Feature::subgroupSizeControl) ? "on" : "off",
           p13.minSubgroupSize, p13.maxSubgroupSize, p13.requiredSubgroupSizeStages);
    return false;
  }
  return true;
}

bool prepareStage(const Object* about, const VkPipelineShaderStageCreateInfo& stage, spv::ExecutionModel model,
                  const char* what, PreparedStage* out) {
  if (!checkSubgroupSize(about, stage, what)) return false;
  // VUID-VkPipelineShaderStageCreateInfo-pName-parameter
  if (!stage.pName) {
    report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-pName-parameter", "%s.pName is NULL", what);
    return false;
  }
  std::vector<uint32_t> storage;
  const std::vector<uint32_t>* code = nullptr;
  if (!shaderStageCode(about, stage, what, storage, &code, &out->codeHash)) return false;
  out->code = std::make_shared<const std::vector<uint32_t>>(*code);
  spirv::CompileRequest& req = out->request;
  req.words = out->code->data();
  req.wordCount = out->code->size();
  req.entryName = stage.pName;
  req.model = model;
  {
    spirv::Module m;
    std::string err;
    // VUID-VkPipelineShaderStageCreateInfo-pName-00707
    if (!m.parse(req.words, req.wordCount, &err) || !m.findEntryPoint(stage.pName, model)) {
      report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-pName-00707",
             "%s.pName \"%s\" is not a %s entry point of the module%s%s", what, stage.pName, modelName(model),
             err.empty() ? "" : ": ", err.c_str());
      return false;
    }
  }
  if (!specialization(about, stage.pSpecializationInfo, what, &req.specialization)) return false;
  out->key = shaderKey(out->codeHash, req);
  return true;
}

CompiledStage compileStage(Device* dev, const PreparedStage& stage, bool mayCompile, PipelineCache* cache,
                           const char* command, const char* what) {
  CompiledStage out;
  const auto start = std::chrono::steady_clock::now();
  bool cacheHit = false;
  std::string error;
  out.shader = compileShared(dev, stage.key, stage.request, mayCompile, &error, cache, &cacheHit, command);
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start).count();
  // VkPipelineCreationFeedback (core in Vulkan 1.3): valid, with the cache hit bit when the code came from the cache.
  out.feedback = {VkPipelineCreationFeedbackFlags(
                      VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT |
                      (cacheHit ? VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT : 0)),
                  uint64_t(ns)};
  if (out.shader) return out;
  if (!mayCompile) {
    // VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT: neither the device nor the cache has the code.
    out.result = VK_PIPELINE_COMPILE_REQUIRED;
    return out;
  }
  report(dev, Severity::Error, nullptr, "%s: entry point \"%s\" cannot be compiled: %s", what,
         stage.request.entryName.c_str(), error.c_str());
  out.result = VK_ERROR_UNKNOWN;
  return out;
}

}  // namespace vkrt
