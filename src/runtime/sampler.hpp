// VkSampler: the create info, kept for the shader compiler's sampling code.
#pragma once

#include "runtime/object.hpp"
#include "runtime/quad_sampling.hpp"

namespace vkrt {

class Sampler : public Object {
 public:
  using Handle = VkSampler;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SAMPLER;

  Sampler(Device* dev, const VkSamplerCreateInfo& info);

  VkSamplerCreateInfo info;  // pNext cleared; kept for the shader compiler's sampling code
  QuadSampler quad;          // what the quad sampler's vector path reads (quad_sampling.hpp)
};

}  // namespace vkrt
