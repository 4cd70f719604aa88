// VkFence, and the process-wide synchronization primitive that fences, semaphores and events share.
//
// Every host-visible sync state (fence signaled, semaphore value, event set) is guarded by sync::mutex() and
// every change is announced on sync::changed(). Waiting for "any" or "all" of several objects is then a single
// condition-variable wait with a predicate over all of them. Queue workers and host waits use the same pair.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>

#include "runtime/object.hpp"

namespace vkrt {

class Queue;

namespace sync {
std::mutex& mutex();
std::condition_variable& changed();
// Waits (with `lock` holding sync::mutex()) until `ready()` is true or `timeoutNs` has passed. UINT64_MAX (or
// any timeout too large to represent as a deadline) waits forever; 0 only evaluates `ready()`. Returns ready().
bool waitFor(std::unique_lock<std::mutex>& lock, uint64_t timeoutNs, const std::function<bool()>& ready);
// Notifies every waiter (call after changing state under the mutex, with or without holding it).
void notifyAll();
}  // namespace sync

class Fence : public Object {
 public:
  using Handle = VkFence;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_FENCE;

  Fence(Device* dev, const VkFenceCreateInfo& info);

  // Guarded by sync::mutex().
  bool signaled = false;
  Queue* pendingOn = nullptr;  // the queue whose submission will signal this fence, while not yet executed
};

}  // namespace vkrt
