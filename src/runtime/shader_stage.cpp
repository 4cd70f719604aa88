#include "runtime/shader_stage.hpp"

#include <algorithm>
#include <chrono>

#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_module.hpp"
#include "spirv/module.hpp"

namespace vkrt {

namespace {

const char* modelName(spv::ExecutionModel m) {
  switch (m) {
    case spv::ExecutionModelGLCompute: return "GLCompute";
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

bool prepareStage(const Object* about, const VkPipelineShaderStageCreateInfo& stage, spv::ExecutionModel model,
                  const char* what, PreparedStage* out) {
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
