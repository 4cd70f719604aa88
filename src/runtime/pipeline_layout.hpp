// VkPipelineLayout.
#pragma once

#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class DescriptorSetLayout;

class PipelineLayout : public Object {
 public:
  using Handle = VkPipelineLayout;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_PIPELINE_LAYOUT;

  // `layouts` are the live set layouts of info.pSetLayouts; each gets a reference.
  PipelineLayout(Device* dev, const VkPipelineLayoutCreateInfo& info, const std::vector<DescriptorSetLayout*>& layouts);
  ~PipelineLayout();

  // Set layouts are referenced (the spec lets the application destroy them after creating the layout, so
  // the layout keeps them alive: see DescriptorSetLayout's reference counting).
  std::vector<DescriptorSetLayout*> setLayouts;
  std::vector<VkPushConstantRange> pushConstantRanges;
  VkPipelineLayoutCreateFlags flags;
  // Position of set s's first dynamic offset in vkCmdBindDescriptorSets' pDynamicOffsets when sets 0..s are
  // bound together (the sum of the dynamic descriptor counts of the sets before s); one extra entry at the
  // end holds the total.
  std::vector<uint32_t> dynamicOffsetStart;
  // The union of the push-constant ranges' stages that cover bytes [offset, offset + size).
  VkShaderStageFlags pushConstantStages(uint32_t offset, uint32_t size) const;
};

}  // namespace vkrt
