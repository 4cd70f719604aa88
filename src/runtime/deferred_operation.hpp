// VkDeferredOperationKHR (VK_KHR_deferred_host_operations).
//
// A deferred command (vkCreateRayTracingPipelinesKHR, the host acceleration structure commands) validates its arguments
// at once, then hands the operation a list of tasks and returns VK_OPERATION_DEFERRED_KHR. The tasks run only on the
// threads that call vkDeferredOperationJoinKHR: each joining thread takes the next task until none is left. Join
// returns
//   VK_SUCCESS          when the operation is complete (this thread finished the last task, or it was done),
//   VK_THREAD_DONE_KHR  when no task is left for this thread but others are still running some,
//   VK_THREAD_IDLE_KHR  never in practice (vkrt never holds work back), reserved by the spec.
// When the last task ends, the operation's finisher runs (it writes pPipelines and computes the result).
#pragma once

#include <functional>
#include <mutex>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt {

class DeferredOperation : public Object {
 public:
  using Handle = VkDeferredOperationKHR;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_DEFERRED_OPERATION_KHR;

  explicit DeferredOperation(Device* dev);

  // Starts an operation: `tasks` run on joining threads; `finish` runs once after the last one, and returns
  // the operation's result. Returns false when an operation is still in progress (VUID ...-03678).
  bool start(std::vector<std::function<void()>> tasks, std::function<VkResult()> finish);

  VkResult join();
  // VK_NOT_READY while in progress; the operation's result once complete (VK_SUCCESS when none was started).
  VkResult result() const;
  // The number of threads that can usefully join now (the tasks not yet taken); 0 when complete.
  uint32_t maxConcurrency() const;
  bool complete() const;

 private:
  mutable std::mutex mutex_;
  std::vector<std::function<void()>> tasks_;
  std::function<VkResult()> finish_;
  size_t next_ = 0;
  size_t running_ = 0;
  bool active_ = false;
  VkResult result_ = VK_SUCCESS;
};

}  // namespace vkrt
