// One path from a VkPipelineShaderStageCreateInfo to a compiled, device-shared shader, for every pipeline kind
// (compute pipelines, ray tracing pipelines and libraries), so that the rules are checked once and alike:
//   prepareStage: the stage's SPIR-V (module or chained VkShaderModuleCreateInfo), pName, the entry point with the
//                 stage's execution model, the VkSpecializationInfo rules (00773, 00774, 04911, pData), giving the
//                 compile request (specialization canonical: sorted by constant id) — at creation time;
//   compileStage: the compiled code (shared per device, or from the application's VkPipelineCache; none with
//                 FAIL_ON_PIPELINE_COMPILE_REQUIRED when it would have to be compiled) and the stage's creation
//                 feedback — at creation time or in a deferred operation.
// Reports name `what`, the stage's path in the command ("vkCreateComputePipelines: pCreateInfos[0].stage").
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "runtime/object.hpp"
#include "runtime/shader_cache.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {

class PipelineCache;

struct PreparedStage {
  std::shared_ptr<const std::vector<uint32_t>> code;  // a copy of the SPIR-V (the application may free its own)
  uint64_t codeHash = 0;
  spirv::CompileRequest request;  // words point into `code`; specialization sorted by constant id
  std::string key;                // the device-wide shader key (shader_cache.hpp)
};

// Returns false after reporting against `about`.
bool prepareStage(const Object* about, const VkPipelineShaderStageCreateInfo& stage, spv::ExecutionModel model,
                  const char* what, PreparedStage* out);

struct CompiledStage {
  std::shared_ptr<const spirv::CompiledShader> shader;  // null when the result is not VK_SUCCESS
  VkResult result = VK_SUCCESS;                         // VK_PIPELINE_COMPILE_REQUIRED or VK_ERROR_UNKNOWN (reported)
  VkPipelineCreationFeedback feedback{};                // VALID, the cache hit bit, the duration
};

CompiledStage compileStage(Device* dev, const PreparedStage& stage, bool mayCompile, PipelineCache* cache,
                           const char* command, const char* what);

}  // namespace vkrt
