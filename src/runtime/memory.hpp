// VkDeviceMemory, and the device address arena it is carved from.
//
// All device memory lives in one process-wide virtual range reserved at a fixed address, so that a device
// address is also the host address of the bytes (shaders dereference buffer device addresses directly)
// and so that a captured opaque address can be given back on replay, in this process or another one.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "runtime/object.hpp"

namespace vkrt {

class Memory : public Object {
 public:
  using Handle = VkDeviceMemory;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DEVICE_MEMORY;

  Memory(Device* dev, uint8_t* base, VkDeviceSize size, uint32_t typeIndex, VkMemoryAllocateFlags flags);
  ~Memory();

  uint8_t* const base;
  const VkDeviceSize size;
  const uint32_t typeIndex;
  const VkMemoryAllocateFlags allocateFlags;
  bool mapped = false;
  VkDeviceSize mappedOffset = 0;
  VkDeviceSize mappedSize = 0;
};

// The arena. `allocate` returns nullptr when the range is exhausted or, for a requested address, when that
// range is not free (or not inside the arena). Without a requested address it takes the lowest free range,
// or the highest one when `fromTop` is set.
namespace arena {
uint8_t* allocate(VkDeviceSize size, uint64_t requestedAddress, bool fromTop);
void release(uint8_t* base, VkDeviceSize size);
// Maps the pages holding [source, source + size), allocated memory, a second time: at requestedAddress, which must
// have source's offset within a page and lie in free pages, or (0) at the highest free range. Returns the address
// of source's first byte there, or nullptr (range not free, offsets differ, or the arena cannot alias). Writes
// through either address are seen through the other; releasing the memory punches its pages out of both.
uint8_t* alias(const uint8_t* source, VkDeviceSize size, uint64_t requestedAddress);
// Unmaps an alias made by `alias` (its address and the size given there) and frees its range.
void unalias(uint8_t* address, VkDeviceSize size);
bool contains(uint64_t address, VkDeviceSize size);
// Whether every byte of [address, address + size) belongs to allocated device memory (so reading it cannot fault).
bool accessible(uint64_t address, VkDeviceSize size);
// The fixed address the arena was reserved at (the same in every process unless the hint was refused).
uint64_t baseAddress();
VkDeviceSize capacity();
// Why [address, address + size) cannot be allocated at that address: the range, rounded to pages, and what is in
// the way (outside the arena, unaligned, or the first part of it that memory allocated earlier holds).
std::string whyUnavailable(uint64_t address, VkDeviceSize size);
}  // namespace arena

}  // namespace vkrt
