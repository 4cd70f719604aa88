// VkPipeline: the base of compute pipelines (runtime/compute_pipeline.hpp) and ray tracing pipelines
// (src/rt/rt_pipeline.hpp). vkDestroyPipeline (pipeline.cpp) deletes through the virtual destructor.
#pragma once

#include "runtime/device.hpp"
#include "runtime/object.hpp"

namespace vkrt {

class PipelineLayout;

class Pipeline : public Object {
 public:
  using Handle = VkPipeline;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PIPELINE;

  Pipeline(Device* dev, VkPipelineBindPoint bindPoint, VkPipelineCreateFlags flags, PipelineLayout* layout)
      : Object(kType, dev->instance, dev), bindPoint(bindPoint), createFlags(flags), layout(layout) {}
  virtual ~Pipeline() = default;

  const VkPipelineBindPoint bindPoint;
  const VkPipelineCreateFlags createFlags;
  PipelineLayout* const layout;
};

}  // namespace vkrt
