// VkShaderModule: validated SPIR-V words.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class ShaderModule : public Object {
 public:
  using Handle = VkShaderModule;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SHADER_MODULE;

  ShaderModule(Device* dev, std::vector<uint32_t> code);

  const std::vector<uint32_t> words;  // validated with SPIRV-Tools at creation
  // A 64-bit content hash of `words` (stable across processes and runs: FNV-1a over the bytes).
  const uint64_t contentHash;
};

// Validates SPIR-V for the Vulkan 1.3 environment. Returns true when valid; otherwise fills `message` with
// the validator's diagnostic (instruction and word offset included). Block layouts follow the standard rules,
// relaxed where `device` enabled scalarBlockLayout or uniformBufferStandardLayout.
bool validateSpirv(const uint32_t* words, size_t wordCount, std::string* message, const Device* device = nullptr);

uint64_t hashBytes(const void* data, size_t size, uint64_t seed = 0xcbf29ce484222325ull);

// Checks a VkShaderModuleCreateInfo (size, alignment, magic number, then SPIRV-Tools validation) and reports
// the first problem against `about` (naming `what`, the calling command). Returns true when the code is valid.
bool checkShaderModuleCreateInfo(const Object* about, const VkShaderModuleCreateInfo& info, const char* what);

// The SPIR-V of a pipeline shader stage: the module's words, or, when `stage.module` is VK_NULL_HANDLE, the
// words of a VkShaderModuleCreateInfo chained to the stage (validated here like vkCreateShaderModule does).
// Returns false after reporting (against `about`, naming `what`) when neither is valid. `storage` receives the
// words in the chained case; `out` then points into it.
bool shaderStageCode(const Object* about, const VkPipelineShaderStageCreateInfo& stage, const char* what,
                     std::vector<uint32_t>& storage, const std::vector<uint32_t>** out, uint64_t* hash = nullptr);

}  // namespace vkrt
