// The compiled shaders of a device, shared by every pipeline and pipeline library that uses them, and the
// consistency of a compiled shader's resources with a pipeline layout.
//
// A shader is keyed by what its code depends on (shaderKey: module content hash and size, entry point,
// execution model, specialization bytes) and compiled once per device: compileShared() compiles on a miss
// (concurrent requests for one key wait for a single compilation) and returns the live code on a hit. With
// `mayCompile` false it returns nullptr on a miss (VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT).
// The code lives while a pipeline (or, for ray tracing, a group record of the device) holds it.
//
// With `cache` (the application's VkPipelineCache), a miss first looks for the compiled code there (loaded
// without LLVM's optimizer and code generator; a damaged entry is ignored and compiled again). `cacheHit` tells
// whether the code was found in `cache`. compileShared never writes to `cache`: a pipeline stores its code with
// storeInCache once it is created (a refused creation leaves the cache as it was).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "runtime/vk.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {

class Device;
class PipelineCache;
class PipelineLayout;

std::string shaderKey(uint64_t codeHash, const spirv::CompileRequest& request);

// `command` names the Vulkan command in reports (a damaged cache entry is reported as a warning).
std::shared_ptr<const spirv::CompiledShader> compileShared(const Device* dev, const std::string& key,
                                                           const spirv::CompileRequest& request, bool mayCompile,
                                                           std::string* error, PipelineCache* cache = nullptr,
                                                           bool* cacheHit = nullptr,
                                                           const char* command = "vkCreateComputePipelines");
// Stores the compiled code in `cache` under its request's key, unless it is there already (a damaged entry is
// replaced). Does nothing without a cache.
void storeInCache(PipelineCache* cache, const spirv::CompileRequest& request, const spirv::CompiledShader& shader);
// Compilations done so far in this process (for tests: a cache hit does not compile).
uint64_t shaderCompileCount();
// Shaders loaded from a VkPipelineCache so far in this process.
uint64_t shaderCacheLoadCount();

// Whether `layout` provides every resource `shader` uses to `stage` ("Pipeline Layout and Shader Interface
// Consistency": a binding at the set and binding number, visible to the stage, of a matching descriptor type,
// with at least as many descriptors). On a mismatch, returns the rule it breaks and describes it in `detail`.
enum class LayoutMismatch { None, Missing, Type, Count };
LayoutMismatch checkLayoutProvides(const PipelineLayout& layout, const spirv::CompiledShader& shader,
                                   VkShaderStageFlagBits stage, std::string* detail);

}  // namespace vkrt
