// The SPIR-V fuzz targets' common path: a module's bytes through vkCreateShaderModule and, for each of its entry
// points, the pipeline of that stage (a compute pipeline, or a ray tracing pipeline with one group holding the
// shader), with specialization constants whose values come from the input too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_device.hpp"
#include "spirv/module.hpp"

namespace vkrt::fuzz {

// The input as SPIR-V words (the tail that is not a whole word is dropped).
inline std::vector<uint32_t> wordsOf(const uint8_t* data, size_t size) {
  std::vector<uint32_t> words(size / 4);
  if (!words.empty()) std::memcpy(words.data(), data, words.size() * 4);
  return words;
}

inline VkShaderStageFlagBits stageOf(spv::ExecutionModel model) {
  switch (model) {
    case spv::ExecutionModelGLCompute: return VK_SHADER_STAGE_COMPUTE_BIT;
    case spv::ExecutionModelRayGenerationKHR: return VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    case spv::ExecutionModelIntersectionKHR: return VK_SHADER_STAGE_INTERSECTION_BIT_KHR;
    case spv::ExecutionModelAnyHitKHR: return VK_SHADER_STAGE_ANY_HIT_BIT_KHR;
    case spv::ExecutionModelClosestHitKHR: return VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR;
    case spv::ExecutionModelMissKHR: return VK_SHADER_STAGE_MISS_BIT_KHR;
    case spv::ExecutionModelCallableKHR: return VK_SHADER_STAGE_CALLABLE_BIT_KHR;
    default: return VkShaderStageFlagBits(0);
  }
}

// Creates the pipeline for one entry point of `module` (destroying it again when it was created). `flags` are the
// pipeline's create flags (VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT stops before the compiler).
// Specialization: every SpecId of the module gets 4 or 8 bytes (`specBytes` as a repeating source of values).
inline VkResult createStagePipeline(VkDevice device, VkPipelineLayout layout, VkShaderModule module,
                                    const spirv::Module& parsed, const spirv::EntryPoint& ep,
                                    VkPipelineCreateFlags flags, const uint8_t* specBytes, size_t specSize) {
  VkShaderStageFlagBits stage = stageOf(ep.model);
  if (!stage) return VK_ERROR_UNKNOWN;
  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint8_t> values;
  for (const auto& [id, d] : parsed.decorations) {
    if (d.specId < 0 || entries.size() >= 16) continue;
    const spirv::Constant* c = parsed.constant(id);
    const spirv::Type* t = c ? parsed.type(c->type) : nullptr;
    uint32_t size = t && (t->kind == spirv::Type::Int || t->kind == spirv::Type::Float) && t->width == 64 ? 8 : 4;
    VkSpecializationMapEntry e{uint32_t(d.specId), uint32_t(values.size()), size};
    for (uint32_t b = 0; b < size; ++b) values.push_back(specSize ? specBytes[(values.size() * 7 + b) % specSize] : 0);
    entries.push_back(e);
  }
  VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), values.size(), values.data()};
  VkPipelineShaderStageCreateInfo st{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  st.stage = stage;
  st.module = module;
  st.pName = ep.name.c_str();
  st.pSpecializationInfo = entries.empty() ? nullptr : &spec;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkResult r;
  if (stage == VK_SHADER_STAGE_COMPUTE_BIT) {
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.flags = flags;
    ci.stage = st;
    ci.layout = layout;
    ci.basePipelineIndex = -1;
    r = vkrt_CreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline);
  } else {
    VkRayTracingShaderGroupCreateInfoKHR g{VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR};
    g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
    switch (stage) {
      case VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR:
        g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
        g.closestHitShader = 0;
        break;
      case VK_SHADER_STAGE_ANY_HIT_BIT_KHR:
        g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
        g.anyHitShader = 0;
        break;
      case VK_SHADER_STAGE_INTERSECTION_BIT_KHR:
        g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
        g.intersectionShader = 0;
        break;
      default:
        g.type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
        g.generalShader = 0;
        break;
    }
    VkRayTracingPipelineInterfaceCreateInfoKHR iface{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_INTERFACE_CREATE_INFO_KHR};
    iface.maxPipelineRayPayloadSize = 64;
    iface.maxPipelineRayHitAttributeSize = 32;
    VkRayTracingPipelineCreateInfoKHR ci{VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR};
    ci.flags = flags | VK_PIPELINE_CREATE_LIBRARY_BIT_KHR;  // a library: one group needs no raygen shader
    ci.stageCount = 1;
    ci.pStages = &st;
    ci.groupCount = 1;
    ci.pGroups = &g;
    ci.maxPipelineRayRecursionDepth = 1;
    ci.pLibraryInterface = &iface;
    ci.layout = layout;
    ci.basePipelineIndex = -1;
    r = vkrt_CreateRayTracingPipelinesKHR(device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline);
  }
  if (pipeline) vkrt_DestroyPipeline(device, pipeline, nullptr);
  return r;
}

// vkCreateShaderModule on `words`; when the module is accepted, a pipeline per entry point (at most `maxEntries`).
inline void modulePipelines(VkDevice device, VkPipelineLayout layout, const std::vector<uint32_t>& words,
                            VkPipelineCreateFlags flags, const uint8_t* specBytes, size_t specSize, size_t maxEntries) {
  VkShaderModuleCreateInfo mci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  mci.codeSize = words.size() * 4;
  mci.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  if (vkrt_CreateShaderModule(device, &mci, nullptr, &module) != VK_SUCCESS) return;
  spirv::Module parsed;
  std::string error;
  // The reader may refuse what SPIRV-Tools' validator lets through (e.g. a LocalSizeId operand that is not a
  // constant): the pipeline then reports it (VUID-VkPipelineShaderStageCreateInfo-pName-00707). Try "main".
  if (!parsed.parse(words.data(), words.size(), &error)) {
    parsed = spirv::Module{};
    parsed.entryPoints.push_back({spv::ExecutionModelGLCompute, 0, "main", {}});
  }
  size_t n = 0;
  for (const spirv::EntryPoint& ep : parsed.entryPoints) {
    if (n++ >= maxEntries) break;
    createStagePipeline(device, layout, module, parsed, ep, flags, specBytes, specSize);
  }
  vkrt_DestroyShaderModule(device, module, nullptr);
}

// A structure-aware mutation for libFuzzer's custom mutator: half of the time libFuzzer's own byte mutations; the
// other half one operand word of one instruction (never a word count or opcode, so the module stays a sequence of
// instructions and SPIRV-Tools' validator accepts far more of the results): a small value, a neighbour, a bit
// flipped, or another word of the module (often an id).
inline size_t mutateSpirv(uint8_t* data, size_t size, size_t maxSize, unsigned seed,
                          size_t (*libFuzzerMutate)(uint8_t*, size_t, size_t)) {
  uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  auto next = [&] {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return uint32_t(state >> 11);
  };
  const size_t n = size / 4;
  if (next() % 2 || n < 6 || (reinterpret_cast<const uint32_t*>(data)[0] != 0x07230203u))
    return libFuzzerMutate(data, size, maxSize);
  uint32_t* words = reinterpret_cast<uint32_t*>(data);  // libFuzzer's buffers are suitably aligned
  // The operand words (not the header, not an instruction's first word).
  std::vector<uint32_t> operands;
  for (size_t at = 5; at < n;) {
    const uint32_t count = words[at] >> 16;
    if (count == 0 || at + count > n) break;
    for (uint32_t i = 1; i < count; ++i) operands.push_back(uint32_t(at + i));
    at += count;
  }
  if (operands.empty()) return libFuzzerMutate(data, size, maxSize);
  uint32_t& w = words[operands[next() % operands.size()]];
  switch (next() % 4) {
    case 0: w = next() % 8; break;
    case 1: w += (next() % 2) ? 1 : -1; break;
    case 2: w ^= 1u << (next() % 32); break;
    default: w = words[operands[next() % operands.size()]]; break;
  }
  return size;
}

}  // namespace vkrt::fuzz
