// Compute pipelines: a compiled shader (shared per device by module content, entry point and specialization,
// see runtime/shader_cache.hpp) plus the create flags dispatches check.
#pragma once

#include <memory>

#include "exec/compute.hpp"
#include "runtime/pipeline.hpp"
#include "runtime/shader_cache.hpp"
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

// What the compute executor runs of a compiled compute shader.
inline exec::ComputeKernel computeKernel(const spirv::CompiledShader& shader) {
  exec::ComputeKernel k;
  k.entry = shader.entry;
  k.groupEntry = shader.groupEntry;
  for (int i = 0; i < 3; ++i) k.localSize[i] = shader.localSize[i];
  k.workgroupMemorySize = shader.workgroupMemorySize;
  k.usesBarrier = shader.usesBarrier;
  k.batchLanes = shader.usesBarrier && shader.groupEntry ? shader.spmdLanes : 0;
  return k;
}

}  // namespace vkrt
