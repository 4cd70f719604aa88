// VkBuffer.
#pragma once

#include "runtime/object.hpp"

namespace vkrt {

class Memory;

class Buffer : public Object {
 public:
  using Handle = VkBuffer;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_BUFFER;

  Buffer(Device* dev, const VkBufferCreateInfo& info);

  const VkDeviceSize size;
  const VkBufferUsageFlags usage;
  const VkBufferCreateFlags flags;
  uint64_t requestedCaptureAddress = 0;  // VkBufferOpaqueCaptureAddressCreateInfo

  Memory* memory = nullptr;
  VkDeviceSize memoryOffset = 0;

  // Host (= device) address of the first byte; null while unbound.
  uint8_t* data() const;
  // Resolves a (offset, range) pair, VK_WHOLE_SIZE allowed, to a byte count; 0 when out of bounds.
  VkDeviceSize rangeFrom(VkDeviceSize offset, VkDeviceSize range) const;

  static constexpr VkDeviceSize kAlignment = 64;
};

}  // namespace vkrt
