// VkQueue: submissions execute in submission order on one worker thread per queue (started on the first
// submission, joined by the destructor).
//
// A batch first waits for its wait semaphores (blocking the worker, so a later batch on this queue cannot
// overtake it), then runs its command buffers, then signals its semaphores; the fence of a submission is
// signaled after its last batch.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class CommandBuffer;
class Fence;
class Semaphore;

struct SemaphoreOp {
  Semaphore* semaphore;
  uint64_t value;  // timeline value (ignored for binary semaphores)
};

struct Batch {
  std::vector<SemaphoreOp> waits;
  std::vector<CommandBuffer*> commandBuffers;
  std::vector<SemaphoreOp> signals;
  Fence* fence = nullptr;  // signaled after this batch (the last batch of a submission)
  // Work done on the worker after the waits, in queue order (a present); `abandoned` when the waits gave up.
  std::function<void(bool abandoned)> hostWork;
};

class Queue : public Object {
 public:
  using Handle = VkQueue;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_QUEUE;

  Queue(Device* dev, uint32_t family, uint32_t index, VkDeviceQueueCreateFlags flags);
  ~Queue();

  const uint32_t family;
  const uint32_t index;
  const VkDeviceQueueCreateFlags flags;

  // Starts the worker thread if it is not running yet; false if the thread could not be created.
  bool startWorker();
  // Appends batches (already validated and accounted for by the submitting call) to the queue.
  void enqueue(std::vector<Batch>&& batches);

  // Blocks until everything submitted to this queue has executed.
  void waitIdle();

  // For deferred destruction (Device::deferIfPending): whether batches enqueued so far have not all completed;
  // if so, `*count` is the number enqueued so far and `*user` a command buffer of that work referring to `o` (or
  // null).
  bool pendingWork(const Object* o, uint64_t* count, const CommandBuffer** user);
  // The number of batches that have completed (their command buffers ran; their signals may follow).
  uint64_t completedCount();

  // True once the destructor runs: a worker blocked on a semaphore or event gives up (read under sync::mutex()).
  bool abandoning() const { return abandon_; }
  // Sets abandoning (the caller holds sync::mutex() and announces the change): the device was lost or is being
  // destroyed.
  void abandonWaits() { abandon_ = true; }

  // Debug-utils label stack (vkQueueBegin/EndDebugUtilsLabelEXT), for reports.
  std::mutex labelMutex;
  std::vector<std::string> labels;

 private:
  void run();
  void execute(Batch& batch);

  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Batch> pending_;
  bool busy_ = false;
  Batch* current_ = nullptr;  // the batch the worker executes, until its commands have completed
  uint64_t enqueued_ = 0;     // batches enqueued
  uint64_t completed_ = 0;    // batches whose commands have completed
  bool stop_ = false;
  bool abandon_ = false;  // guarded by sync::mutex()
  std::thread worker_;
};

}  // namespace vkrt
