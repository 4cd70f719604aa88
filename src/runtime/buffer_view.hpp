// VkBufferView: a formatted range of a buffer, kept for texel-buffer descriptors.
#pragma once

#include "runtime/object.hpp"

namespace vkrt {

class Buffer;
struct FormatInfo;

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

}  // namespace vkrt
