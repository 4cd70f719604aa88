// VkImageView, VkBufferView and VkSampler: small objects that keep what shaders and descriptors need.
#pragma once

#include "icd/object.hpp"

namespace vkrt {

class Image;
class Buffer;
struct FormatInfo;

class ImageView : public Object {
 public:
  using Handle = VkImageView;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_IMAGE_VIEW;

  ImageView(Device* dev, const VkImageViewCreateInfo& info, Image* image);

  Image* const image;
  const VkImageViewType viewType;
  const VkFormat format;
  const VkComponentMapping components;
  const VkImageSubresourceRange range;  // VK_REMAINING_* resolved
};

class BufferView : public Object {
 public:
  using Handle = VkBufferView;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_BUFFER_VIEW;

  BufferView(Device* dev, const VkBufferViewCreateInfo& info, Buffer* buffer, VkDeviceSize range);

  Buffer* const buffer;
  const VkFormat format;
  const VkDeviceSize offset;
  const VkDeviceSize range;  // VK_WHOLE_SIZE resolved
  const FormatInfo* const formatInfo;
};

class Sampler : public Object {
 public:
  using Handle = VkSampler;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SAMPLER;

  Sampler(Device* dev, const VkSamplerCreateInfo& info);

  VkSamplerCreateInfo info;  // pNext cleared; kept for the shader compiler's sampling code
};

}  // namespace vkrt
