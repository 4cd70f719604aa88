// VkQueryPool: timestamp queries (VK_QUERY_TYPE_TIMESTAMP), occlusion queries (VK_QUERY_TYPE_OCCLUSION: the samples
// that passed the per-fragment tests between vkCmdBeginQuery and vkCmdEndQuery, src/gfx/query_commands.cpp) and
// acceleration structure property queries (compacted size, serialization size, size, bottom-level pointers). Timestamps
// are nanoseconds of CLOCK_MONOTONIC (timestampPeriod 1.0, 64 valid bits). Each query is a value and an availability
// flag; commands write them on the queue worker, the host reads them with vkGetQueryPoolResults.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>

#include "runtime/object.hpp"

namespace vkrt {

class QueryPool : public Object {
 public:
  using Handle = VkQueryPool;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_QUERY_POOL;

  QueryPool(Device* dev, const VkQueryPoolCreateInfo& info);

  const VkQueryType type;
  const uint32_t count;

  void reset(uint32_t first, uint32_t n);
  void writeTimestamp(uint32_t query);
  // Makes `query` available with `value` (acceleration structure property queries).
  void writeValue(uint32_t query, uint64_t value);
  // Occlusion queries: begin() makes `query` unavailable with a count of 0; the rasterizer adds the samples that
  // pass to counter(query) (atomically, from its workers); end() makes it available with the count.
  void begin(uint32_t query);
  std::atomic<uint64_t>* counter(uint32_t query) { return &slots_[query].value; }
  void end(uint32_t query);
  bool available(uint32_t query) const;
  uint64_t value(uint32_t query) const;
  // Blocks until `query` is available.
  void waitAvailable(uint32_t query) const;

  // Writes the results of queries [first, first + n) as vkGetQueryPoolResults / vkCmdCopyQueryPoolResults
  // define them. `wait` blocks for each query. Returns false when some query was unavailable (VK_NOT_READY).
  bool copyResults(uint32_t first, uint32_t n, uint8_t* dst, VkDeviceSize stride, VkQueryResultFlags flags) const;

  static uint64_t now();  // CLOCK_MONOTONIC in ns

 private:
  struct Slot {
    std::atomic<uint64_t> value{0};
    std::atomic<uint32_t> available{0};
  };
  std::unique_ptr<Slot[]> slots_;
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
};

// The bytes one query's result takes with `flags` (value plus availability).
VkDeviceSize queryResultSize(VkQueryResultFlags flags);

}  // namespace vkrt
