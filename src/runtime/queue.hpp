// VkQueue.
#pragma once

#include "icd/object.hpp"

namespace vkrt {

class Queue : public Object {
 public:
  using Handle = VkQueue;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_QUEUE;

  Queue(Device* dev, uint32_t family, uint32_t index, VkDeviceQueueCreateFlags flags);
  ~Queue();

  const uint32_t family;
  const uint32_t index;
  const VkDeviceQueueCreateFlags flags;

  // Blocks until everything submitted to this queue has executed.
  void waitIdle();
};

}  // namespace vkrt
