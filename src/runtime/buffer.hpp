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
  ~Buffer();

  const VkDeviceSize size;
  const VkBufferUsageFlags usage;
  const VkBufferCreateFlags flags;
  uint64_t requestedCaptureAddress = 0;  // VkBufferOpaqueCaptureAddressCreateInfo

  Memory* memory = nullptr;
  VkDeviceSize memoryOffset = 0;

  // A second mapping of the bound bytes (arena::alias) that is the buffer's device address, for a buffer created
  // with VK_BUFFER_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT: at its requested opaque capture address where its
  // memory does not lie there, or (captured) in the range kept for capture/replay where its memory is ordinary.
  uint8_t* alias = nullptr;

  // Host address of the first byte; null while unbound.
  uint8_t* data() const;
  // Device address of the first byte (the host address of the same bytes, through `alias` where there is one).
  uint8_t* deviceAddress() const { return alias ? alias : data(); }
  // Resolves a (offset, range) pair, VK_WHOLE_SIZE allowed, to a byte count; 0 when out of bounds.
  VkDeviceSize rangeFrom(VkDeviceSize offset, VkDeviceSize range) const;

  static constexpr VkDeviceSize kAlignment = 64;
};

}  // namespace vkrt
