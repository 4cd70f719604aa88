// Compute pipelines: a compiled shader (shared per device by module content, entry point and specialization,
// see runtime/shader_cache.hpp) plus the create flags dispatches check.
#pragma once

#include <memory>

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

}  // namespace vkrt
