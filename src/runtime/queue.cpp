#include "runtime/queue.hpp"

#include "runtime/device.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Queue::Queue(Device* dev, uint32_t fam, uint32_t idx, VkDeviceQueueCreateFlags f)
    : Object(kType, dev->instance, dev), family(fam), index(idx), flags(f) {}

Queue::~Queue() = default;

void Queue::waitIdle() {}

}  // namespace vkrt
