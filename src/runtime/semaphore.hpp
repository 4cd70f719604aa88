// VkSemaphore: binary and timeline semaphores.
//
// Device-side state (what queue workers and host waits see) is `value`: for a binary semaphore 1 = signaled,
// 0 = unsignaled; for a timeline semaphore the counter. Submission-time bookkeeping (what has been submitted but
// not executed yet) is kept separately, so that vkQueueSubmit can check the rules that talk about submitted
// operations. Everything is guarded by sync::mutex() (runtime/fence.hpp).
#pragma once

#include <cstdint>
#include <set>

#include "runtime/object.hpp"

namespace vkrt {

class Semaphore : public Object {
 public:
  using Handle = VkSemaphore;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_SEMAPHORE;

  Semaphore(Device* dev, VkSemaphoreType type, uint64_t initialValue);

  const VkSemaphoreType type;
  bool timeline() const { return type == VK_SEMAPHORE_TYPE_TIMELINE; }

  // Guarded by sync::mutex().
  uint64_t value = 0;
  // Binary: a signal has been submitted (or the semaphore is signaled) and no submitted wait consumed it yet.
  bool binarySignalSubmitted = false;
  // Timeline: values of submitted signal operations that have not executed yet.
  std::multiset<uint64_t> pendingSignals;
  // Submitted batches that refer to this semaphore and have not completed.
  uint32_t inFlight = 0;

  // Queue worker side: blocks until the wait is satisfied (consuming a binary signal) or `*abandon` (read under
  // sync::mutex()) becomes true, then returns false.
  bool waitOnQueue(uint64_t waitValue, const bool* abandon);
};

}  // namespace vkrt
