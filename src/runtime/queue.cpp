#include "runtime/queue.hpp"

#include <map>
#include <system_error>

#include "runtime/alloc.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/fence.hpp"
#include "runtime/report.hpp"
#include "runtime/semaphore.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

Queue::Queue(Device* dev, uint32_t fam, uint32_t idx, VkDeviceQueueCreateFlags f)
    : Object(kType, dev->instance, dev), family(fam), index(idx), flags(f) {}

Queue::~Queue() {
  {
    std::lock_guard lock(sync::mutex());
    abandon_ = true;  // a batch still blocked on a semaphore or event gives up
  }
  sync::notifyAll();
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
}

bool Queue::startWorker() {
  std::lock_guard lock(mutex_);
  if (worker_.joinable()) return true;
  try {
    worker_ = std::thread([this] { run(); });
  } catch (const std::system_error&) {
    return false;
  }
  return true;
}

void Queue::enqueue(std::vector<Batch>&& batches) {
  {
    std::lock_guard lock(mutex_);
    for (Batch& b : batches) pending_.push_back(std::move(b));
    enqueued_ += batches.size();
  }
  cv_.notify_all();
}

void Queue::waitIdle() {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return pending_.empty() && !busy_; });
}

bool Queue::pendingWork(const Object* o, uint64_t* count, const CommandBuffer** user) {
  std::lock_guard lock(mutex_);
  if (completed_ == enqueued_) return false;
  *count = enqueued_;
  *user = nullptr;
  auto scan = [&](const Batch& b) {
    for (const CommandBuffer* cb : b.commandBuffers)
      if (!*user && cb->refersTo(o)) *user = cb;
  };
  if (current_) scan(*current_);
  for (const Batch& b : pending_) scan(b);
  return true;
}

uint64_t Queue::completedCount() {
  std::lock_guard lock(mutex_);
  return completed_;
}

void Queue::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    cv_.wait(lock, [&] { return stop_ || !pending_.empty(); });
    if (stop_) return;
    Batch batch = std::move(pending_.front());
    pending_.pop_front();
    busy_ = true;
    current_ = &batch;
    lock.unlock();
    execute(batch);
    lock.lock();
    busy_ = false;
    cv_.notify_all();
  }
}

void Queue::execute(Batch& batch) {
  bool abandoned = false;
  for (const SemaphoreOp& w : batch.waits) {
    if (!w.semaphore->waitOnQueue(w.value, &abandon_)) {
      abandoned = true;
      break;
    }
  }
  if (!abandoned) {
    for (CommandBuffer* cb : batch.commandBuffers) {
      ExecState st;
      st.queue = this;
      try {
        cb->execute(st);
      } catch (const std::exception& e) {
        report(cb, Severity::Error, nullptr,
               "queue execution: a command failed (%s); the rest of the command buffer "
               "was skipped",
               e.what());
      }
    }
  }
  for (CommandBuffer* cb : batch.commandBuffers) cb->markCompleted();
  if (batch.hostWork) batch.hostWork(abandoned);
  // The batch's work is done: objects destroyed while it was pending go now, before its signals let a waiter
  // observe completion (a destroy after the wait then finds nothing pending).
  {
    std::lock_guard lock(mutex_);
    current_ = nullptr;
    ++completed_;
  }
  device->runDeferred(false);
  // Signals, and the end of this batch's references, in one step: once a waiter sees a signal it may destroy
  // the objects, so nothing is touched after the lock is released.
  {
    std::lock_guard lock(sync::mutex());
    for (const SemaphoreOp& w : batch.waits) --w.semaphore->inFlight;
    for (const SemaphoreOp& s : batch.signals) {
      Semaphore* sem = s.semaphore;
      if (sem->timeline()) {
        auto it = sem->pendingSignals.find(s.value);
        if (it != sem->pendingSignals.end()) sem->pendingSignals.erase(it);
        if (s.value > sem->value) sem->value = s.value;
      } else {
        sem->value = 1;
      }
      --sem->inFlight;
    }
    if (batch.fence) {
      batch.fence->signaled = true;
      batch.fence->pendingOn = nullptr;
    }
  }
  sync::notifyAll();
}

}  // namespace vkrt

using namespace vkrt;

namespace {

// Checks the batches of one vkQueueSubmit(2) call against the current state of their command buffers,
// semaphores and fence; on success accounts for them (pending states, submitted signals, in-flight references)
// and enqueues them. Returns the call's result.
VkResult submit(Queue* q, std::vector<Batch>& batches, VkFence fenceHandle, bool v2) {
  const char* fn = v2 ? "vkQueueSubmit2" : "vkQueueSubmit";
  // Lost Device: nothing is submitted, and nothing the call names changes.
  if (q->device->lost) return VK_ERROR_DEVICE_LOST;
  Fence* fence = nullptr;
  if (fenceHandle) {
    fence = fromHandle<Fence>(fenceHandle);
    if (!fence) {
      report(q, Severity::Error, v2 ? "VUID-vkQueueSubmit2-fence-parameter" : "VUID-vkQueueSubmit-fence-parameter",
             "%s: fence 0x%llx is not a live VkFence", fn, (unsigned long long)rawHandle(fenceHandle));
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  std::map<const CommandBuffer*, uint32_t> uses;
  for (uint32_t si = 0; si < batches.size(); ++si)
    for (uint32_t i = 0; i < batches[si].commandBuffers.size(); ++i)
      if (!batches[si].commandBuffers[i]->checkSubmittable(q, v2, si, i, uses)) return VK_ERROR_VALIDATION_FAILED_EXT;
  if (!q->startWorker()) return VK_ERROR_OUT_OF_HOST_MEMORY;

  std::unique_lock lock(sync::mutex());
  if (fence) {
    // VUID-vkQueueSubmit-fence-00063, VUID-vkQueueSubmit2-fence-04894
    if (fence->signaled) {
      report(fence, Severity::Error, v2 ? "VUID-vkQueueSubmit2-fence-04894" : "VUID-vkQueueSubmit-fence-00063",
             "%s: the fence is signaled; reset it before submitting it", fn);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-vkQueueSubmit-fence-00064, VUID-vkQueueSubmit2-fence-04895
    if (fence->pendingOn) {
      report(fence, Severity::Error, v2 ? "VUID-vkQueueSubmit2-fence-04895" : "VUID-vkQueueSubmit-fence-00064",
             "%s: the fence is already associated with a submission that has not completed", fn);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // Binary semaphore states as they will be after each batch, in submission order.
  std::map<Semaphore*, bool> binary;
  auto binaryState = [&](Semaphore* s) -> bool& {
    auto it = binary.find(s);
    if (it == binary.end()) it = binary.emplace(s, s->binarySignalSubmitted).first;
    return it->second;
  };
  for (uint32_t si = 0; si < batches.size(); ++si) {
    for (uint32_t i = 0; i < batches[si].waits.size(); ++i) {
      Semaphore* s = batches[si].waits[i].semaphore;
      if (s->timeline()) continue;  // timeline waits may come before their signal (wait-before-signal)
      bool& signaled = binaryState(s);
      // VUID-vkQueueSubmit-pWaitSemaphores-03238, VUID-vkQueueSubmit2-semaphore-03873
      if (!signaled) {
        report(
            s, Severity::Error, v2 ? "VUID-vkQueueSubmit2-semaphore-03873" : "VUID-vkQueueSubmit-pWaitSemaphores-03238",
            "%s: pSubmits[%u] wait %u: the binary semaphore has no submitted signal operation to wait for", fn, si, i);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      signaled = false;
    }
    for (uint32_t i = 0; i < batches[si].signals.size(); ++i) {
      const SemaphoreOp& op = batches[si].signals[i];
      if (op.semaphore->timeline()) {
        // VUID-VkSubmitInfo-pSignalSemaphores-03242, VUID-VkSubmitInfo2-semaphore-03882
        if (op.value <= op.semaphore->value) {
          report(op.semaphore, Severity::Error,
                 v2 ? "VUID-VkSubmitInfo2-semaphore-03882" : "VUID-VkSubmitInfo-pSignalSemaphores-03242",
                 "%s: pSubmits[%u] signal %u: value %llu is not greater than the timeline semaphore's current value "
                 "%llu",
                 fn, si, i, (unsigned long long)op.value, (unsigned long long)op.semaphore->value);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
        continue;
      }
      bool& signaled = binaryState(op.semaphore);
      // VUID-vkQueueSubmit-pSignalSemaphores-00067, VUID-vkQueueSubmit2-semaphore-03868
      if (signaled) {
        report(op.semaphore, Severity::Error,
               v2 ? "VUID-vkQueueSubmit2-semaphore-03868" : "VUID-vkQueueSubmit-pSignalSemaphores-00067",
               "%s: pSubmits[%u] signal %u: the binary semaphore is already signaled (or has a pending signal that "
               "no wait consumes)",
               fn, si, i);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      signaled = true;
    }
  }
  // Accepted: account for everything, then enqueue.
  for (auto& [s, signaled] : binary) s->binarySignalSubmitted = signaled;
  for (Batch& b : batches) {
    for (SemaphoreOp& w : b.waits) ++w.semaphore->inFlight;
    for (SemaphoreOp& s : b.signals) {
      ++s.semaphore->inFlight;
      if (s.semaphore->timeline()) s.semaphore->pendingSignals.insert(s.value);
    }
  }
  if (fence) {
    fence->pendingOn = q;
    if (batches.empty()) batches.emplace_back();  // a fence alone: signaled after all earlier work
    batches.back().fence = fence;
  }
  lock.unlock();
  for (Batch& b : batches)
    for (CommandBuffer* cb : b.commandBuffers) cb->markSubmitted();
  q->enqueue(std::move(batches));
  return VK_SUCCESS;
}

Semaphore* liveSemaphore(const Object* about, VkSemaphore h, const char* fn, const char* vuid, uint32_t si,
                         uint32_t i) {
  Semaphore* s = fromHandle<Semaphore>(h);
  if (!s)
    report(about, Severity::Error, vuid, "%s: pSubmits[%u] semaphore %u (0x%llx) is not a live VkSemaphore", fn, si, i,
           (unsigned long long)rawHandle(h));
  return s;
}

CommandBuffer* liveCommandBuffer(const Object* about, VkCommandBuffer h, const char* fn, const char* vuid, uint32_t si,
                                 uint32_t i) {
  CommandBuffer* cb = fromHandle<CommandBuffer>(h);
  if (!cb)
    report(about, Severity::Error, vuid, "%s: pSubmits[%u] command buffer %u (0x%llx) is not a live VkCommandBuffer",
           fn, si, i, (unsigned long long)rawHandle(h));
  return cb;
}

Queue* liveQueue(VkQueue h, const char* fn, const char* vuid) {
  Queue* q = fromHandle<Queue>(h);
  if (!q)
    report(nullptr, Severity::Error, vuid, "%s: 0x%llx is not a live VkQueue", fn, (unsigned long long)rawHandle(h));
  return q;
}

}  // namespace

extern "C" {

// vkQueueBindSparse (core 1.0): vkrt's one queue family has no VK_QUEUE_SPARSE_BINDING_BIT (no sparse feature is
// supported, so no sparse resource exists), so every call breaks VUID-vkQueueBindSparse-queuetype: reported, and
// nothing is waited on, bound or signalled.
VKAPI_ATTR VkResult VKAPI_CALL vkrt_QueueBindSparse(VkQueue queue, uint32_t bindInfoCount,
                                                    const VkBindSparseInfo* pBindInfo, VkFence fence) {
  const char* fn = "vkQueueBindSparse";
  Queue* q = liveQueue(queue, fn, "VUID-vkQueueBindSparse-queue-parameter");
  if (!q) return VK_ERROR_VALIDATION_FAILED_EXT;
  report(q, Severity::Error, "VUID-vkQueueBindSparse-queuetype",
         "%s: the queue's family has no VK_QUEUE_SPARSE_BINDING_BIT (vkrt supports no sparse binding); %u bind "
         "infos, fence 0x%llx: nothing is done",
         fn, bindInfoCount, (unsigned long long)rawHandle(fence));
  return VK_ERROR_VALIDATION_FAILED_EXT;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_QueueSubmit(VkQueue queue, uint32_t submitCount, const VkSubmitInfo* pSubmits,
                                                VkFence fence) {
  const char* fn = "vkQueueSubmit";
  Queue* q = liveQueue(queue, fn, "VUID-vkQueueSubmit-queue-parameter");
  if (!q) return VK_ERROR_VALIDATION_FAILED_EXT;
  std::vector<Batch> batches(submitCount);
  for (uint32_t si = 0; si < submitCount; ++si) {
    const VkSubmitInfo& info = pSubmits[si];
    Batch& b = batches[si];
    auto* tl = findInChain<VkTimelineSemaphoreSubmitInfo>(info.pNext, VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO);
    for (uint32_t i = 0; i < info.waitSemaphoreCount; ++i) {
      Semaphore* s =
          liveSemaphore(q, info.pWaitSemaphores[i], fn, "VUID-VkSubmitInfo-pWaitSemaphores-parameter", si, i);
      if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
      // VUID-VkSubmitInfo-pWaitDstStageMask-00078
      if (info.pWaitDstStageMask[i] & VK_PIPELINE_STAGE_HOST_BIT) {
        report(q, Severity::Error, "VUID-VkSubmitInfo-pWaitDstStageMask-00078",
               "%s: pSubmits[%u].pWaitDstStageMask[%u] includes VK_PIPELINE_STAGE_HOST_BIT", fn, si, i);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      uint64_t value = 0;
      if (s->timeline()) {
        // VUID-VkSubmitInfo-pWaitSemaphores-03239
        if (!tl) {
          report(s, Severity::Error, "VUID-VkSubmitInfo-pWaitSemaphores-03239",
                 "%s: pSubmits[%u] waits on a timeline semaphore without a VkTimelineSemaphoreSubmitInfo", fn, si);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
        // VUID-VkSubmitInfo-pNext-03240
        if (tl->waitSemaphoreValueCount != info.waitSemaphoreCount) {
          report(s, Severity::Error, "VUID-VkSubmitInfo-pNext-03240",
                 "%s: pSubmits[%u] has %u wait semaphores but waitSemaphoreValueCount %u", fn, si,
                 info.waitSemaphoreCount, tl->waitSemaphoreValueCount);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
        value = tl->pWaitSemaphoreValues[i];
      }
      b.waits.push_back({s, value});
    }
    for (uint32_t i = 0; i < info.commandBufferCount; ++i) {
      CommandBuffer* cb =
          liveCommandBuffer(q, info.pCommandBuffers[i], fn, "VUID-VkSubmitInfo-pCommandBuffers-parameter", si, i);
      if (!cb) return VK_ERROR_VALIDATION_FAILED_EXT;
      b.commandBuffers.push_back(cb);
    }
    for (uint32_t i = 0; i < info.signalSemaphoreCount; ++i) {
      Semaphore* s =
          liveSemaphore(q, info.pSignalSemaphores[i], fn, "VUID-VkSubmitInfo-pSignalSemaphores-parameter", si, i);
      if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
      uint64_t value = 0;
      if (s->timeline()) {
        // VUID-VkSubmitInfo-pWaitSemaphores-03239
        if (!tl) {
          report(s, Severity::Error, "VUID-VkSubmitInfo-pWaitSemaphores-03239",
                 "%s: pSubmits[%u] signals a timeline semaphore without a VkTimelineSemaphoreSubmitInfo", fn, si);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
        // VUID-VkSubmitInfo-pNext-03241
        if (tl->signalSemaphoreValueCount != info.signalSemaphoreCount) {
          report(s, Severity::Error, "VUID-VkSubmitInfo-pNext-03241",
                 "%s: pSubmits[%u] has %u signal semaphores but signalSemaphoreValueCount %u", fn, si,
                 info.signalSemaphoreCount, tl->signalSemaphoreValueCount);
          return VK_ERROR_VALIDATION_FAILED_EXT;
        }
        value = tl->pSignalSemaphoreValues[i];
      }
      b.signals.push_back({s, value});
    }
  }
  return submit(q, batches, fence, false);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_QueueSubmit2(VkQueue queue, uint32_t submitCount, const VkSubmitInfo2* pSubmits,
                                                 VkFence fence) {
  const char* fn = "vkQueueSubmit2";
  Queue* q = liveQueue(queue, fn, "VUID-vkQueueSubmit2-queue-parameter");
  if (!q) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkQueueSubmit2-synchronization2-03866
  if (!q->device->enabled(Feature::synchronization2)) {
    report(q, Severity::Error, "VUID-vkQueueSubmit2-synchronization2-03866",
           "%s: the synchronization2 feature is not enabled", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<Batch> batches(submitCount);
  for (uint32_t si = 0; si < submitCount; ++si) {
    const VkSubmitInfo2& info = pSubmits[si];
    Batch& b = batches[si];
    for (uint32_t i = 0; i < info.waitSemaphoreInfoCount; ++i) {
      const VkSemaphoreSubmitInfo& w = info.pWaitSemaphoreInfos[i];
      Semaphore* s = liveSemaphore(q, w.semaphore, fn, "VUID-VkSemaphoreSubmitInfo-semaphore-parameter", si, i);
      if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
      b.waits.push_back({s, s->timeline() ? w.value : 0});
    }
    for (uint32_t i = 0; i < info.commandBufferInfoCount; ++i) {
      CommandBuffer* cb = liveCommandBuffer(q, info.pCommandBufferInfos[i].commandBuffer, fn,
                                            "VUID-VkCommandBufferSubmitInfo-commandBuffer-parameter", si, i);
      if (!cb) return VK_ERROR_VALIDATION_FAILED_EXT;
      b.commandBuffers.push_back(cb);
    }
    for (uint32_t i = 0; i < info.signalSemaphoreInfoCount; ++i) {
      const VkSemaphoreSubmitInfo& sg = info.pSignalSemaphoreInfos[i];
      Semaphore* s = liveSemaphore(q, sg.semaphore, fn, "VUID-VkSemaphoreSubmitInfo-semaphore-parameter", si, i);
      if (!s) return VK_ERROR_VALIDATION_FAILED_EXT;
      b.signals.push_back({s, s->timeline() ? sg.value : 0});
    }
  }
  return submit(q, batches, fence, true);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_QueueWaitIdle(VkQueue queue) {
  Queue* q = liveQueue(queue, "vkQueueWaitIdle", "VUID-vkQueueWaitIdle-queue-parameter");
  if (!q) return VK_ERROR_VALIDATION_FAILED_EXT;
  q->waitIdle();
  return q->device->lost ? VK_ERROR_DEVICE_LOST : VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_QueueBeginDebugUtilsLabelEXT(VkQueue queue, const VkDebugUtilsLabelEXT* pLabelInfo) {
  Queue* q = liveQueue(queue, "vkQueueBeginDebugUtilsLabelEXT", "VUID-vkQueueBeginDebugUtilsLabelEXT-queue-parameter");
  if (!q) return;
  std::lock_guard lock(q->labelMutex);
  q->labels.emplace_back(pLabelInfo->pLabelName ? pLabelInfo->pLabelName : "");
}

VKAPI_ATTR void VKAPI_CALL vkrt_QueueEndDebugUtilsLabelEXT(VkQueue queue) {
  Queue* q = liveQueue(queue, "vkQueueEndDebugUtilsLabelEXT", "VUID-vkQueueEndDebugUtilsLabelEXT-queue-parameter");
  if (!q) return;
  std::lock_guard lock(q->labelMutex);
  // VUID-vkQueueEndDebugUtilsLabelEXT-None-01911
  if (q->labels.empty()) {
    report(q, Severity::Error, "VUID-vkQueueEndDebugUtilsLabelEXT-None-01911",
           "vkQueueEndDebugUtilsLabelEXT: the queue has no open debug label region");
    return;
  }
  q->labels.pop_back();
}

VKAPI_ATTR void VKAPI_CALL vkrt_QueueInsertDebugUtilsLabelEXT(VkQueue queue, const VkDebugUtilsLabelEXT*) {
  liveQueue(queue, "vkQueueInsertDebugUtilsLabelEXT", "VUID-vkQueueInsertDebugUtilsLabelEXT-queue-parameter");
}

}  // extern "C"
