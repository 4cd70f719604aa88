#include "runtime/query_pool.hpp"

#include <time.h>

#include <cstring>

#include "runtime/alloc.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

QueryPool::QueryPool(Device* dev, const VkQueryPoolCreateInfo& info)
    : Object(kType, dev->instance, dev),
      type(info.queryType),
      count(info.queryCount),
      slots_(new Slot[info.queryCount]) {}

uint64_t QueryPool::now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return uint64_t(ts.tv_sec) * 1000000000ull + uint64_t(ts.tv_nsec);
}

void QueryPool::reset(uint32_t first, uint32_t n) {
  std::lock_guard lock(mutex_);
  for (uint32_t i = first; i < first + n; ++i) {
    slots_[i].available.store(0, std::memory_order_relaxed);
    slots_[i].value.store(0, std::memory_order_relaxed);
  }
}

void QueryPool::writeTimestamp(uint32_t query) { writeValue(query, now()); }

void QueryPool::begin(uint32_t query) {
  std::lock_guard lock(mutex_);
  slots_[query].available.store(0, std::memory_order_relaxed);
  slots_[query].value.store(0, std::memory_order_relaxed);
}

void QueryPool::end(uint32_t query) {
  {
    std::lock_guard lock(mutex_);
    slots_[query].available.store(1, std::memory_order_release);
  }
  cv_.notify_all();
}

void QueryPool::writeValue(uint32_t query, uint64_t value) {
  {
    std::lock_guard lock(mutex_);
    slots_[query].value.store(value, std::memory_order_relaxed);
    slots_[query].available.store(1, std::memory_order_release);
  }
  cv_.notify_all();
}

bool QueryPool::available(uint32_t query) const { return slots_[query].available.load(std::memory_order_acquire) != 0; }
uint64_t QueryPool::value(uint32_t query) const { return slots_[query].value.load(std::memory_order_relaxed); }

void QueryPool::waitAvailable(uint32_t query) const {
  std::unique_lock lock(mutex_);
  cv_.wait(lock, [&] { return available(query); });
}

VkDeviceSize queryResultSize(VkQueryResultFlags flags) {
  VkDeviceSize word = (flags & VK_QUERY_RESULT_64_BIT) ? 8 : 4;
  return (flags & VK_QUERY_RESULT_WITH_AVAILABILITY_BIT) ? 2 * word : word;
}

bool QueryPool::copyResults(uint32_t first, uint32_t n, uint8_t* dst, VkDeviceSize stride,
                            VkQueryResultFlags flags) const {
  bool all = true;
  const bool is64 = flags & VK_QUERY_RESULT_64_BIT;
  auto put = [&](uint8_t* p, uint64_t v) {
    if (is64) {
      std::memcpy(p, &v, 8);
    } else {
      uint32_t w = static_cast<uint32_t>(v);  // the low 32 bits, as the spec says for 32-bit results
      std::memcpy(p, &w, 4);
    }
  };
  for (uint32_t i = 0; i < n; ++i) {
    uint32_t q = first + i;
    if (flags & VK_QUERY_RESULT_WAIT_BIT) waitAvailable(q);
    bool avail = available(q);
    uint8_t* p = dst + i * stride;
    // Unavailable: the value is not written, but with PARTIAL (occlusion queries; invalid for timestamps), which
    // asks for "an intermediate result value between zero and the final result value": 0.
    if (avail)
      put(p, value(q));
    else if (flags & VK_QUERY_RESULT_PARTIAL_BIT)
      put(p, 0);
    all = all && avail;
    if (flags & VK_QUERY_RESULT_WITH_AVAILABILITY_BIT) put(p + (is64 ? 8 : 4), avail ? 1 : 0);
  }
  return all;
}

}  // namespace vkrt

using namespace vkrt;

namespace {

// The range checks shared by every command taking (firstQuery, queryCount). Reports and returns false.
bool checkRange(const QueryPool* pool, uint32_t first, uint32_t n, const char* cmd, const char* vuidFirst,
                const char* vuidSum) {
  if (first >= pool->count) {
    report(pool, Severity::Error, vuidFirst, "%s: firstQuery %u is not less than the pool's %u queries", cmd, first,
           pool->count);
    return false;
  }
  if (uint64_t(first) + n > pool->count) {
    report(pool, Severity::Error, vuidSum, "%s: firstQuery %u + queryCount %u exceeds the pool's %u queries", cmd,
           first, n, pool->count);
    return false;
  }
  return true;
}

QueryPool* livePool(const Object* about, VkQueryPool h, const char* cmd, const char* vuid) {
  return liveOrReport<QueryPool>(about, h, cmd, vuid);
}

// Records a timestamp write after checking the pool type and the query index.
void recordTimestamp(CommandBuffer* cb, QueryPool* pool, uint32_t query, const char* cmd, const char* vuidType,
                     const char* vuidQuery) {
  if (pool->type != VK_QUERY_TYPE_TIMESTAMP) {
    report(pool, Severity::Error, vuidType, "%s: the pool's queryType is %d, not VK_QUERY_TYPE_TIMESTAMP", cmd,
           pool->type);
    return;
  }
  if (query >= pool->count) {
    report(pool, Severity::Error, vuidQuery, "%s: query %u is not less than the pool's %u queries", cmd, query,
           pool->count);
    return;
  }
  cb->record([pool, query](ExecState&) { pool->writeTimestamp(query); });
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateQueryPool(VkDevice device, const VkQueryPoolCreateInfo* pCreateInfo,
                                                    const VkAllocationCallbacks* pAllocator, VkQueryPool* pQueryPool) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-VkQueryPoolCreateInfo-queryCount-02763
  if (pCreateInfo->queryCount == 0) {
    report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryCount-02763",
           "vkCreateQueryPool: queryCount must be greater than 0");
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  switch (pCreateInfo->queryType) {
    case VK_QUERY_TYPE_TIMESTAMP: break;
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR:
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR:
      if (dev->extensionEnabled(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME)) break;
      // VUID-VkQueryPoolCreateInfo-queryType-parameter
      report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryType-parameter",
             "vkCreateQueryPool: queryType %d needs VK_KHR_acceleration_structure enabled", pCreateInfo->queryType);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV:
      if (dev->extensionEnabled(VK_NV_RAY_TRACING_EXTENSION_NAME)) break;
      // VUID-VkQueryPoolCreateInfo-queryType-parameter
      report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryType-parameter",
             "vkCreateQueryPool: queryType %d needs VK_NV_ray_tracing enabled", pCreateInfo->queryType);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR:
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR:
      if (dev->extensionEnabled(VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME)) break;
      // VUID-VkQueryPoolCreateInfo-queryType-parameter
      report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryType-parameter",
             "vkCreateQueryPool: queryType %d needs VK_KHR_ray_tracing_maintenance1 enabled", pCreateInfo->queryType);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    case VK_QUERY_TYPE_PIPELINE_STATISTICS:
      // VUID-VkQueryPoolCreateInfo-queryType-00791
      report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryType-00791",
             "vkCreateQueryPool: VK_QUERY_TYPE_PIPELINE_STATISTICS needs the pipelineStatisticsQuery feature, which "
             "vkrt does not support");
      return VK_ERROR_VALIDATION_FAILED_EXT;
    case VK_QUERY_TYPE_OCCLUSION: break;
    default:
      // VUID-VkQueryPoolCreateInfo-queryType-parameter
      report(dev, Severity::Error, "VUID-VkQueryPoolCreateInfo-queryType-parameter",
             "vkCreateQueryPool: queryType %d is not supported (no enabled extension provides it)",
             pCreateInfo->queryType);
      return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  QueryPool* pool;
  try {
    pool = createObject<QueryPool>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, *pCreateInfo);
  } catch (...) {
    pool = nullptr;
  }
  if (!pool) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pQueryPool = toHandle(pool);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyQueryPool(VkDevice device, VkQueryPool queryPool,
                                                 const VkAllocationCallbacks* pAllocator) {
  if (!queryPool) return;
  // VUID-vkDestroyQueryPool-queryPool-parameter
  QueryPool* pool = livePool(fromHandle<Device>(device), queryPool, "vkDestroyQueryPool",
                             "VUID-vkDestroyQueryPool-queryPool-parameter");
  if (pool) destroyObject(pool, pAllocator);
}

VKAPI_ATTR void VKAPI_CALL vkrt_ResetQueryPool(VkDevice device, VkQueryPool queryPool, uint32_t firstQuery,
                                               uint32_t queryCount) {
  Device* dev = fromHandleUnchecked<Device>(device);
  // VUID-vkResetQueryPool-queryPool-parameter
  QueryPool* pool = livePool(dev, queryPool, "vkResetQueryPool", "VUID-vkResetQueryPool-queryPool-parameter");
  if (!pool) return;
  // VUID-vkResetQueryPool-None-02665
  if (!dev->enabled(Feature::hostQueryReset)) {
    report(pool, Severity::Error, "VUID-vkResetQueryPool-None-02665",
           "vkResetQueryPool: the hostQueryReset feature is not enabled");
    return;
  }
  // VUID-vkResetQueryPool-firstQuery-02666, VUID-vkResetQueryPool-firstQuery-02667
  if (!checkRange(pool, firstQuery, queryCount, "vkResetQueryPool", "VUID-vkResetQueryPool-firstQuery-02666",
                  "VUID-vkResetQueryPool-firstQuery-02667"))
    return;
  pool->reset(firstQuery, queryCount);
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetQueryPoolResults(VkDevice device, VkQueryPool queryPool, uint32_t firstQuery,
                                                        uint32_t queryCount, size_t dataSize, void* pData,
                                                        VkDeviceSize stride, VkQueryResultFlags flags) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const char* cmd = "vkGetQueryPoolResults";
  // VUID-vkGetQueryPoolResults-queryPool-parameter
  QueryPool* pool = livePool(dev, queryPool, cmd, "VUID-vkGetQueryPoolResults-queryPool-parameter");
  if (!pool) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkGetQueryPoolResults-firstQuery-00813, VUID-vkGetQueryPoolResults-firstQuery-00816
  if (!checkRange(pool, firstQuery, queryCount, cmd, "VUID-vkGetQueryPoolResults-firstQuery-00813",
                  "VUID-vkGetQueryPoolResults-firstQuery-00816"))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkGetQueryPoolResults-queryType-00818
  if (pool->type == VK_QUERY_TYPE_TIMESTAMP && (flags & VK_QUERY_RESULT_PARTIAL_BIT)) {
    report(pool, Severity::Error, "VUID-vkGetQueryPoolResults-queryType-00818",
           "%s: VK_QUERY_RESULT_PARTIAL_BIT is not allowed for timestamp queries", cmd);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  const bool is64 = flags & VK_QUERY_RESULT_64_BIT;
  // VUID-vkGetQueryPoolResults-flags-00815, VUID-vkGetQueryPoolResults-flags-02828
  VkDeviceSize align = is64 ? 8 : 4;
  if (stride % align || reinterpret_cast<uintptr_t>(pData) % align) {
    report(pool, Severity::Error,
           is64 ? "VUID-vkGetQueryPoolResults-flags-00815" : "VUID-vkGetQueryPoolResults-flags-02828",
           "%s: pData %p and stride %llu must be multiples of %llu", cmd, pData, (unsigned long long)stride,
           (unsigned long long)align);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkGetQueryPoolResults-dataSize-00817
  VkDeviceSize need = queryCount ? (queryCount - 1) * stride + queryResultSize(flags) : 0;
  if (dataSize < need) {
    report(pool, Severity::Error, "VUID-vkGetQueryPoolResults-dataSize-00817",
           "%s: dataSize %zu is smaller than the %llu bytes %u results with stride %llu take", cmd, dataSize,
           (unsigned long long)need, queryCount, (unsigned long long)stride);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return pool->copyResults(firstQuery, queryCount, static_cast<uint8_t*>(pData), stride, flags) ? VK_SUCCESS
                                                                                                : VK_NOT_READY;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdResetQueryPool(VkCommandBuffer commandBuffer, VkQueryPool queryPool,
                                                  uint32_t firstQuery, uint32_t queryCount) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdResetQueryPool");
  if (!cb) return;
  // VUID-vkCmdResetQueryPool-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass("vkCmdResetQueryPool", "VUID-vkCmdResetQueryPool-renderpass")) return;
  // VUID-vkCmdResetQueryPool-queryPool-parameter
  QueryPool* pool = livePool(cb, queryPool, "vkCmdResetQueryPool", "VUID-vkCmdResetQueryPool-queryPool-parameter");
  if (!pool) return;
  // VUID-vkCmdResetQueryPool-firstQuery-00796, VUID-vkCmdResetQueryPool-firstQuery-00797
  if (!checkRange(pool, firstQuery, queryCount, "vkCmdResetQueryPool", "VUID-vkCmdResetQueryPool-firstQuery-00796",
                  "VUID-vkCmdResetQueryPool-firstQuery-00797"))
    return;
  cb->record([pool, firstQuery, queryCount](ExecState&) { pool->reset(firstQuery, queryCount); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdWriteTimestamp(VkCommandBuffer commandBuffer, VkPipelineStageFlagBits pipelineStage,
                                                  VkQueryPool queryPool, uint32_t query) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdWriteTimestamp");
  if (!cb) return;
  // VUID-vkCmdWriteTimestamp-queryPool-parameter
  QueryPool* pool = livePool(cb, queryPool, "vkCmdWriteTimestamp", "VUID-vkCmdWriteTimestamp-queryPool-parameter");
  if (!pool) return;
  if (!cb->familySupportsStages(pipelineStage, "vkCmdWriteTimestamp", "VUID-vkCmdWriteTimestamp-pipelineStage-04074",
                                "pipelineStage"))
    return;
  // VUID-vkCmdWriteTimestamp-queryPool-01416, VUID-vkCmdWriteTimestamp-query-04904
  recordTimestamp(cb, pool, query, "vkCmdWriteTimestamp", "VUID-vkCmdWriteTimestamp-queryPool-01416",
                  "VUID-vkCmdWriteTimestamp-query-04904");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdWriteTimestamp2(VkCommandBuffer commandBuffer, VkPipelineStageFlags2 stage,
                                                   VkQueryPool queryPool, uint32_t query) {
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdWriteTimestamp2");
  if (!cb) return;
  // VUID-vkCmdWriteTimestamp2-synchronization2-03858
  if (!cb->device->enabled(Feature::synchronization2)) {
    report(cb, Severity::Error, "VUID-vkCmdWriteTimestamp2-synchronization2-03858",
           "vkCmdWriteTimestamp2: the synchronization2 feature is not enabled");
    return;
  }
  // VUID-vkCmdWriteTimestamp2-stage-03859
  if (stage & (stage - 1)) {
    report(cb, Severity::Error, "VUID-vkCmdWriteTimestamp2-stage-03859",
           "vkCmdWriteTimestamp2: stage 0x%llx names more than one pipeline stage", (unsigned long long)stage);
    return;
  }
  // VUID-vkCmdWriteTimestamp2-queryPool-parameter
  QueryPool* pool = livePool(cb, queryPool, "vkCmdWriteTimestamp2", "VUID-vkCmdWriteTimestamp2-queryPool-parameter");
  if (!pool) return;
  if (!cb->familySupportsStages(stage, "vkCmdWriteTimestamp2", "VUID-vkCmdWriteTimestamp2-stage-03860", "stage"))
    return;
  // VUID-vkCmdWriteTimestamp2-queryPool-03861, VUID-vkCmdWriteTimestamp2-query-04903
  recordTimestamp(cb, pool, query, "vkCmdWriteTimestamp2", "VUID-vkCmdWriteTimestamp2-queryPool-03861",
                  "VUID-vkCmdWriteTimestamp2-query-04903");
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyQueryPoolResults(VkCommandBuffer commandBuffer, VkQueryPool queryPool,
                                                        uint32_t firstQuery, uint32_t queryCount, VkBuffer dstBuffer,
                                                        VkDeviceSize dstOffset, VkDeviceSize stride,
                                                        VkQueryResultFlags flags) {
  const char* cmd = "vkCmdCopyQueryPoolResults";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, cmd);
  if (!cb) return;
  // VUID-vkCmdCopyQueryPoolResults-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(cmd, "VUID-vkCmdCopyQueryPoolResults-renderpass")) return;
  // VUID-vkCmdCopyQueryPoolResults-queryPool-parameter
  QueryPool* pool = livePool(cb, queryPool, cmd, "VUID-vkCmdCopyQueryPoolResults-queryPool-parameter");
  if (!pool) return;
  Buffer* buf = fromHandle<Buffer>(dstBuffer);
  // VUID-vkCmdCopyQueryPoolResults-dstBuffer-parameter
  if (!buf) {
    report(cb, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-dstBuffer-parameter",
           "%s: dstBuffer 0x%llx is not a live VkBuffer", cmd, (unsigned long long)rawHandle(dstBuffer));
    return;
  }
  // VUID-vkCmdCopyQueryPoolResults-firstQuery-00820, VUID-vkCmdCopyQueryPoolResults-firstQuery-00821
  if (!checkRange(pool, firstQuery, queryCount, cmd, "VUID-vkCmdCopyQueryPoolResults-firstQuery-00820",
                  "VUID-vkCmdCopyQueryPoolResults-firstQuery-00821"))
    return;
  // VUID-vkCmdCopyQueryPoolResults-queryType-00827
  if (pool->type == VK_QUERY_TYPE_TIMESTAMP && (flags & VK_QUERY_RESULT_PARTIAL_BIT)) {
    report(pool, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-queryType-00827",
           "%s: VK_QUERY_RESULT_PARTIAL_BIT is not allowed for timestamp queries", cmd);
    return;
  }
  // VUID-vkCmdCopyQueryPoolResults-dstBuffer-00825
  if (!(buf->usage & VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {
    report(buf, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-dstBuffer-00825",
           "%s: dstBuffer lacks VK_BUFFER_USAGE_TRANSFER_DST_BIT (usage 0x%x)", cmd, buf->usage);
    return;
  }
  // VUID-vkCmdCopyQueryPoolResults-dstBuffer-00826
  if (!buf->memory) {
    report(buf, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-dstBuffer-00826",
           "%s: dstBuffer is not bound to memory", cmd);
    return;
  }
  // VUID-vkCmdCopyQueryPoolResults-dstOffset-00819
  if (dstOffset >= buf->size) {
    report(buf, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-dstOffset-00819",
           "%s: dstOffset %llu is not less than the buffer size %llu", cmd, (unsigned long long)dstOffset,
           (unsigned long long)buf->size);
    return;
  }
  const bool is64 = flags & VK_QUERY_RESULT_64_BIT;
  // VUID-vkCmdCopyQueryPoolResults-flags-00822, VUID-vkCmdCopyQueryPoolResults-flags-00823
  if (dstOffset % (is64 ? 8 : 4) || stride % (is64 ? 8 : 4)) {
    report(buf, Severity::Error,
           is64 ? "VUID-vkCmdCopyQueryPoolResults-flags-00823" : "VUID-vkCmdCopyQueryPoolResults-flags-00822",
           "%s: dstOffset %llu and stride %llu must be multiples of %d", cmd, (unsigned long long)dstOffset,
           (unsigned long long)stride, is64 ? 8 : 4);
    return;
  }
  // VUID-vkCmdCopyQueryPoolResults-dstBuffer-00824
  VkDeviceSize need = queryCount ? (queryCount - 1) * stride + queryResultSize(flags) : 0;
  if (need > buf->size - dstOffset) {
    report(buf, Severity::Error, "VUID-vkCmdCopyQueryPoolResults-dstBuffer-00824",
           "%s: %u results with stride %llu need %llu bytes from dstOffset %llu; the buffer has %llu", cmd, queryCount,
           (unsigned long long)stride, (unsigned long long)need, (unsigned long long)dstOffset,
           (unsigned long long)buf->size);
    return;
  }
  // At execution every earlier command of the queue has run, so WAIT cannot wait for anything more: the copy
  // reports what is available then.
  VkQueryResultFlags execFlags = flags & ~VK_QUERY_RESULT_WAIT_BIT;
  cb->record([pool, buf, firstQuery, queryCount, dstOffset, stride, execFlags](ExecState&) {
    pool->copyResults(firstQuery, queryCount, buf->data() + dstOffset, stride, execFlags);
  });
}

}  // extern "C"
