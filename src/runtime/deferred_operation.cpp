#include "runtime/deferred_operation.hpp"

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

DeferredOperation::DeferredOperation(Device* dev) : Object(kType, dev->instance, dev) {}

bool DeferredOperation::start(std::vector<std::function<void()>> tasks, std::function<VkResult()> finish) {
  std::lock_guard lock(mutex_);
  if (active_) return false;
  tasks_ = std::move(tasks);
  finish_ = std::move(finish);
  next_ = 0;
  running_ = 0;
  active_ = true;
  result_ = VK_NOT_READY;
  return true;
}

VkResult DeferredOperation::join() {
  std::unique_lock lock(mutex_);
  if (!active_) return VK_SUCCESS;
  while (next_ < tasks_.size()) {
    std::function<void()>& task = tasks_[next_++];
    ++running_;
    lock.unlock();
    task();
    lock.lock();
    --running_;
  }
  if (running_ > 0 || !active_) return active_ ? VK_THREAD_DONE_KHR : VK_SUCCESS;
  // This thread ended the last task: finish the operation.
  result_ = finish_ ? finish_() : VK_SUCCESS;
  tasks_.clear();
  finish_ = nullptr;
  active_ = false;
  return VK_SUCCESS;
}

VkResult DeferredOperation::result() const {
  std::lock_guard lock(mutex_);
  return active_ ? VK_NOT_READY : result_;
}

uint32_t DeferredOperation::maxConcurrency() const {
  std::lock_guard lock(mutex_);
  if (!active_) return 0;
  size_t left = tasks_.size() - next_;
  return left ? static_cast<uint32_t>(left) : 1;
}

bool DeferredOperation::complete() const {
  std::lock_guard lock(mutex_);
  return !active_;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateDeferredOperationKHR(VkDevice device, const VkAllocationCallbacks* pAllocator,
                                                               VkDeferredOperationKHR* pDeferredOperation) {
  Device* dev = fromHandleUnchecked<Device>(device);
  auto* op = createObject<DeferredOperation>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev);
  if (!op) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pDeferredOperation = toHandle(op);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyDeferredOperationKHR(VkDevice device, VkDeferredOperationKHR operation,
                                                            const VkAllocationCallbacks* pAllocator) {
  if (!operation) return;
  DeferredOperation* op = fromHandle<DeferredOperation>(operation);
  // VUID-vkDestroyDeferredOperationKHR-operation-parameter
  if (!op) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDestroyDeferredOperationKHR-operation-parameter",
           "vkDestroyDeferredOperationKHR: 0x%llx is not a live VkDeferredOperationKHR",
           (unsigned long long)rawHandle(operation));
    return;
  }
  // VUID-vkDestroyDeferredOperationKHR-operation-03436
  if (!op->complete()) {
    report(op, Severity::Error, "VUID-vkDestroyDeferredOperationKHR-operation-03436",
           "vkDestroyDeferredOperationKHR: the operation is not complete (%u task(s) not yet taken); join it first",
           op->maxConcurrency());
    return;
  }
  destroyObject(op, pAllocator);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_DeferredOperationJoinKHR(VkDevice device, VkDeferredOperationKHR operation) {
  DeferredOperation* op = fromHandle<DeferredOperation>(operation);
  // VUID-vkDeferredOperationJoinKHR-operation-parameter
  if (!op) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkDeferredOperationJoinKHR-operation-parameter",
           "vkDeferredOperationJoinKHR: 0x%llx is not a live VkDeferredOperationKHR",
           (unsigned long long)rawHandle(operation));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return op->join();
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetDeferredOperationResultKHR(VkDevice device, VkDeferredOperationKHR operation) {
  DeferredOperation* op = fromHandle<DeferredOperation>(operation);
  // VUID-vkGetDeferredOperationResultKHR-operation-parameter
  if (!op) {
    report(fromHandle<Device>(device), Severity::Error, "VUID-vkGetDeferredOperationResultKHR-operation-parameter",
           "vkGetDeferredOperationResultKHR: 0x%llx is not a live VkDeferredOperationKHR",
           (unsigned long long)rawHandle(operation));
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return op->result();
}

VKAPI_ATTR uint32_t VKAPI_CALL vkrt_GetDeferredOperationMaxConcurrencyKHR(VkDevice device,
                                                                          VkDeferredOperationKHR operation) {
  DeferredOperation* op = fromHandle<DeferredOperation>(operation);
  if (!op) {
    report(fromHandle<Device>(device), Severity::Error,
           "VUID-vkGetDeferredOperationMaxConcurrencyKHR-operation-parameter",
           "vkGetDeferredOperationMaxConcurrencyKHR: 0x%llx is not a live VkDeferredOperationKHR",
           (unsigned long long)rawHandle(operation));
    return 0;
  }
  return op->maxConcurrency();
}

}  // extern "C"
