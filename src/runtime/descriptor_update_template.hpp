// VkDescriptorUpdateTemplate: a list of (binding, element, count, type, offset, stride) entries applied to a
// descriptor set from one block of application memory: an allocated set (vkUpdateDescriptorSetWithTemplate), or
// push descriptors (VK_DESCRIPTOR_UPDATE_TEMPLATE_TYPE_PUSH_DESCRIPTORS_KHR, vkCmdPushDescriptorSetWithTemplateKHR).
#pragma once

#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class DescriptorSet;
class DescriptorSetLayout;

class DescriptorUpdateTemplate : public Object {
 public:
  using Handle = VkDescriptorUpdateTemplate;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_UPDATE_TEMPLATE;

  // `layout` is info.descriptorSetLayout, or for push descriptors set info.set of info.pipelineLayout.
  DescriptorUpdateTemplate(Device* dev, const VkDescriptorUpdateTemplateCreateInfo& info, DescriptorSetLayout* layout);
  ~DescriptorUpdateTemplate();

  DescriptorSetLayout* const layout;  // referenced
  const VkDescriptorUpdateTemplateType type;
  const VkPipelineBindPoint bindPoint;  // push descriptors only
  std::vector<VkDescriptorUpdateTemplateEntry> entries;

  // Checks every entry's descriptors from `pData` against `set`, then writes them all; reports the first problem
  // (naming `fn`) and writes nothing. Returns whether it wrote.
  bool write(DescriptorSet* set, const void* pData, const char* fn) const;
};

}  // namespace vkrt
