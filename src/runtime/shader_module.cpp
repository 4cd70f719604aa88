#include "runtime/shader_module.hpp"

#include <spirv-tools/libspirv.hpp>

#include <cstdio>
#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "spirv/newer_tokens.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

uint64_t hashBytes(const void* data, size_t size, uint64_t seed) {
  auto* p = static_cast<const uint8_t*>(data);
  uint64_t h = seed;
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

ShaderModule::ShaderModule(Device* dev, std::vector<uint32_t> code)
    : Object(kType, dev->instance, dev),
      words(std::move(code)),
      contentHash(hashBytes(words.data(), words.size() * sizeof(uint32_t))) {}

bool validateSpirv(const uint32_t* words, size_t wordCount, std::string* message, const Device* device) {
  spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_3);
  std::string first;
  tools.SetMessageConsumer([&](spv_message_level_t level, const char*, const spv_position_t& pos, const char* msg) {
    if (level > SPV_MSG_ERROR || !first.empty()) return;  // keep the first error
    char where[64];
    std::snprintf(where, sizeof where, "at word %zu: ", pos.index);
    first = std::string(where) + (msg ? msg : "");
  });
  spvtools::ValidatorOptions options;
  // The layouts the device's features allow (the compiler follows the explicit Offset/ArrayStride decorations
  // whatever the rules they were chosen by).
  if (device && device->enabled(Feature::scalarBlockLayout)) options.SetScalarBlockLayout(true);
  if (device && device->enabled(Feature::uniformBufferStandardLayout)) options.SetUniformBufferStandardLayout(true);
  if (device && device->enabled(Feature::workgroupMemoryExplicitLayoutScalarBlockLayout))
    options.SetWorkgroupScalarBlockLayout(true);
  // SPIR-V newer than Debian's SPIRV-Tools (SPV_KHR_ray_tracing_position_fetch) is checked by vkrt and hidden from
  // the validator, which then validates everything else as it would (spirv/newer_tokens.hpp).
  std::vector<uint32_t> hidden(words, words + wordCount);
  std::string newer;
  if (!spirv::hideNewerTokensForValidation(hidden, &newer)) {
    if (message) *message = newer;
    return false;
  }
  bool ok = tools.Validate(hidden.data(), hidden.size(), options);
  if (!ok && message) *message = first.empty() ? "SPIRV-Tools rejected the module" : first;
  return ok;
}

bool checkShaderModuleCreateInfo(const Object* about, const VkShaderModuleCreateInfo& info, const char* what) {
  // VUID-VkShaderModuleCreateInfo-codeSize-01085
  if (info.codeSize == 0) {
    report(about, Severity::Error, "VUID-VkShaderModuleCreateInfo-codeSize-01085",
           "%s: codeSize must be greater than 0", what);
    return false;
  }
  // VUID-VkShaderModuleCreateInfo-pCode-01376
  if (info.codeSize % 4) {
    report(about, Severity::Error, "VUID-VkShaderModuleCreateInfo-pCode-01376",
           "%s: codeSize %zu is not a multiple of 4", what, info.codeSize);
    return false;
  }
  // VUID-VkShaderModuleCreateInfo-pCode-01377: SPIR-V starts with its magic number (vkrt takes no GLSL).
  if (info.codeSize < 20 || !info.pCode || info.pCode[0] != 0x07230203u) {
    report(about, Severity::Error, "VUID-VkShaderModuleCreateInfo-pCode-01377",
           "%s: pCode is not SPIR-V (first word 0x%08x, %zu bytes; SPIR-V starts with magic 0x07230203 and a "
           "5-word header)",
           what, info.pCode && info.codeSize >= 4 ? info.pCode[0] : 0u, info.codeSize);
    return false;
  }
  std::string message;
  // VUID-VkShaderModuleCreateInfo-pCode-01378
  const Device* device = about && about->objectType == VK_OBJECT_TYPE_DEVICE ? static_cast<const Device*>(about)
                         : about                                             ? about->device
                                                                             : nullptr;
  if (!validateSpirv(info.pCode, info.codeSize / 4, &message, device)) {
    report(about, Severity::Error, "VUID-VkShaderModuleCreateInfo-pCode-01378", "%s: invalid SPIR-V for Vulkan 1.3: %s",
           what, message.c_str());
    return false;
  }
  return true;
}

bool shaderStageCode(const Object* about, const VkPipelineShaderStageCreateInfo& stage, const char* what,
                     std::vector<uint32_t>& storage, const std::vector<uint32_t>** out, uint64_t* hash) {
  if (stage.module) {
    ShaderModule* m = fromHandle<ShaderModule>(stage.module);
    // VUID-VkPipelineShaderStageCreateInfo-module-parameter
    if (!m) {
      report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-module-parameter",
             "%s: module 0x%llx is not a live VkShaderModule", what, (unsigned long long)rawHandle(stage.module));
      return false;
    }
    *out = &m->words;
    if (hash) *hash = m->contentHash;
    return true;
  }
  auto* ci = findInChain<VkShaderModuleCreateInfo>(stage.pNext, VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  // VUID-VkPipelineShaderStageCreateInfo-stage-06845 (no module and no chained VkShaderModuleCreateInfo)
  if (!ci) {
    report(about, Severity::Error, "VUID-VkPipelineShaderStageCreateInfo-stage-06845",
           "%s: module is VK_NULL_HANDLE and no VkShaderModuleCreateInfo is chained to the stage", what);
    return false;
  }
  if (!checkShaderModuleCreateInfo(about, *ci, what)) return false;
  storage.assign(ci->pCode, ci->pCode + ci->codeSize / 4);
  *out = &storage;
  if (hash) *hash = hashBytes(storage.data(), storage.size() * sizeof(uint32_t));
  return true;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateShaderModule(VkDevice device, const VkShaderModuleCreateInfo* pCreateInfo,
                                                       const VkAllocationCallbacks* pAllocator,
                                                       VkShaderModule* pShaderModule) {
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!checkShaderModuleCreateInfo(dev, *pCreateInfo, "vkCreateShaderModule")) return VK_ERROR_INVALID_SHADER_NV;
  std::vector<uint32_t> words;
  try {
    words.assign(pCreateInfo->pCode, pCreateInfo->pCode + pCreateInfo->codeSize / 4);
  } catch (const std::bad_alloc&) {
    return VK_ERROR_OUT_OF_HOST_MEMORY;
  }
  auto* m = createObject<ShaderModule>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, std::move(words));
  if (!m) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pShaderModule = toHandle(m);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyShaderModule(VkDevice device, VkShaderModule shaderModule,
                                                    const VkAllocationCallbacks* pAllocator) {
  if (!shaderModule) return;
  ShaderModule* m = fromHandle<ShaderModule>(shaderModule);
  // VUID-vkDestroyShaderModule-shaderModule-parameter
  if (!m) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyShaderModule-shaderModule-parameter",
           "vkDestroyShaderModule: 0x%llx is not a live VkShaderModule", (unsigned long long)rawHandle(shaderModule));
    return;
  }
  destroyObject(m, pAllocator);
}

}  // extern "C"
