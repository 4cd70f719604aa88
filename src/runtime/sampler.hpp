// VkSampler: the create info, kept for the shader compiler's sampling code.
#pragma once

#include "runtime/object.hpp"

namespace vkrt {

class Sampler : public Object {
 public:
  using Handle = VkSampler;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SAMPLER;

  Sampler(Device* dev, const VkSamplerCreateInfo& info);

  VkSamplerCreateInfo info;  // pNext cleared; kept for the shader compiler's sampling code
};

}  // namespace vkrt
