// VkPipelineLayout.
#pragma once

#include <vector>

#include "icd/object.hpp"

namespace vkrt {

class DescriptorSetLayout;

class PipelineLayout : public Object {
 public:
  using Handle = VkPipelineLayout;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PIPELINE_LAYOUT;

  PipelineLayout(Device* dev, const VkPipelineLayoutCreateInfo& info);

  // Set layouts are referenced (the spec lets the application destroy them after creating the layout, so
  // the layout keeps what it needs of them: see DescriptorSetLayout's reference counting).
  std::vector<DescriptorSetLayout*> setLayouts;
  std::vector<VkPushConstantRange> pushConstantRanges;
  VkPipelineLayoutCreateFlags flags;
};

}  // namespace vkrt
