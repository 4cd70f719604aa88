// VkCommandPool: owns the command buffers allocated from it (freed with it).
#pragma once

#include <set>

#include "runtime/object.hpp"

namespace vkrt {

class CommandBuffer;

class CommandPool : public Object {
 public:
  using Handle = VkCommandPool;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_COMMAND_POOL;

  CommandPool(Device* dev, const VkCommandPoolCreateInfo& info, const VkAllocationCallbacks* alloc);

  const VkCommandPoolCreateFlags flags;
  const uint32_t queueFamilyIndex;
  bool canResetBuffers() const { return (flags & VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT) != 0; }

  // The command buffers allocated from the pool and not freed (externally synchronized with the pool).
  std::set<CommandBuffer*> buffers;
  // The allocator the pool was created with; command buffers are allocated with it.
  VkAllocationCallbacks allocator{};
  bool hasAllocator = false;
  const VkAllocationCallbacks* alloc() const { return hasAllocator ? &allocator : nullptr; }

  // Destroys a command buffer of this pool (unlinking it from primaries/secondaries).
  void freeBuffer(CommandBuffer* cb);
  // Whether any command buffer of the pool is pending; names the first in `*which`.
  bool anyPending(CommandBuffer** which) const;
};

}  // namespace vkrt
