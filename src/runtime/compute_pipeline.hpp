// Compute pipelines: a compiled shader (shared per device by module content, entry point and specialization,
// see ShaderCache) plus the create flags dispatches check.
#pragma once

#include <memory>

#include "runtime/pipeline.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {

class PipelineCache;

class ComputePipeline : public Pipeline {
 public:
  ComputePipeline(Device* dev, VkPipelineCreateFlags flags, PipelineLayout* layout,
                  std::shared_ptr<const spirv::CompiledShader> shader)
      : Pipeline(dev, VK_PIPELINE_BIND_POINT_COMPUTE, flags, layout), shader(std::move(shader)) {}

  const std::shared_ptr<const spirv::CompiledShader> shader;
};

// Compiled shaders of a device, by key (module content hash, entry point, stage, specialization bytes): a
// shader is compiled once and shared by every pipeline that uses it while any of them lives.
// compileShared() compiles on a miss (concurrent requests for one key wait for a single compilation); with
// `mayCompile` false it returns nullptr on a miss (VK_PIPELINE_CREATE_FAIL_ON_PIPELINE_COMPILE_REQUIRED_BIT).
//
// With `cache` (the application's VkPipelineCache), a miss first looks for the compiled code there (loaded
// without LLVM's optimizer and code generator; a damaged entry is ignored, compiled again and replaced), and
// newly compiled code is stored there. `cacheHit` tells whether the code was found in `cache`.
std::shared_ptr<const spirv::CompiledShader> compileShared(const Device* dev, const std::string& key,
                                                           const spirv::CompileRequest& request, bool mayCompile,
                                                           std::string* error, PipelineCache* cache = nullptr,
                                                           bool* cacheHit = nullptr);
// Compilations done so far in this process (for tests: a cache hit does not compile).
uint64_t shaderCompileCount();
// Shaders loaded from a VkPipelineCache so far in this process.
uint64_t shaderCacheLoadCount();

}  // namespace vkrt
