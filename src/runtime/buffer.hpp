// VkBuffer.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "exec/shader_debug.hpp"
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

  // In the table of live device address ranges (VKRT_SHADER_CHECKS=bda; bound with
  // VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT while the setting is on).
  bool addressListed = false;
};

// VKRT_SHADER_CHECKS=bda: the device address ranges of `owner`'s (a Device's) live buffers with
// VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT whose memory is allocated (exec::AddressTableSource; once per command).
void deviceAddressRanges(const void* owner, std::vector<exec::AddressRange>* out);
// Calls fn with the listed buffer of handle `handle` while it cannot be destroyed; false when none is listed (a report
// naming the buffer nearest an address, after the command).
bool withAddressBuffer(uint64_t handle, const std::function<void(const Buffer&)>& fn);

}  // namespace vkrt
