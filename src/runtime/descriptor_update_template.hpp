// VkDescriptorUpdateTemplate: a list of (binding, element, count, type, offset, stride) entries applied to a
// descriptor set from one block of application memory.
#pragma once

#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class DescriptorSetLayout;

class DescriptorUpdateTemplate : public Object {
 public:
  using Handle = VkDescriptorUpdateTemplate;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DESCRIPTOR_UPDATE_TEMPLATE;

  DescriptorUpdateTemplate(Device* dev, const VkDescriptorUpdateTemplateCreateInfo& info, DescriptorSetLayout* layout);
  ~DescriptorUpdateTemplate();

  DescriptorSetLayout* const layout;  // referenced
  std::vector<VkDescriptorUpdateTemplateEntry> entries;
};

}  // namespace vkrt
