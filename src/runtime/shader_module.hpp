// VkShaderModule: validated SPIR-V words.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "icd/object.hpp"

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
// the validator's diagnostic (instruction and word offset included).
bool validateSpirv(const uint32_t* words, size_t wordCount, std::string* message);

uint64_t hashBytes(const void* data, size_t size, uint64_t seed = 0xcbf29ce484222325ull);

}  // namespace vkrt
