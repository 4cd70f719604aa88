// vkCmdBeginQuery / vkCmdEndQuery: occlusion queries ("Occlusion Queries"), the only query type vkrt begins and
// ends. Between the two, every draw adds the samples that pass the per-fragment tests to the query's counter
// (raster::Draw::samplesPassed); the count is exact, with or without VK_QUERY_CONTROL_PRECISE_BIT. Inside a render
// pass instance with multiview the query takes one index per view of the subpass: the first gets the total, the
// others 0 (one of the distributions the spec allows).
#include <bit>

#include "gfx/graphics_state.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/command_pool.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/query_pool.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;
using namespace vkrt::gfx;

namespace {

struct QueryVuids {
  const char* fn;
  const char* pool;   // -queryPool-parameter
  const char* query;  // the index is below queryCount
  const char* views;  // the index plus the subpass's views fits the pool
};

// The pool and the number of queries the command uses, after the checks both commands share; null after reporting.
QueryPool* checkQuery(CommandBuffer* cb, VkQueryPool queryPool, uint32_t query, const QueryVuids& v, uint32_t* views) {
  QueryPool* pool = liveOrReport<QueryPool>(cb, queryPool, v.fn, v.pool);
  if (!pool) return nullptr;
  if (query >= pool->count) {
    report(pool, Severity::Error, v.query, "%s: query %u is not less than the pool's %u queries", v.fn, query,
           pool->count);
    return nullptr;
  }
  const PassRecordState& pass = recordState(cb).pass;
  *views = pass.active && pass.viewMask ? uint32_t(std::popcount(pass.viewMask)) : 1;
  if (uint64_t(query) + *views > pool->count) {
    report(pool, Severity::Error, v.views,
           "%s: query %u and the %u views of the subpass's view mask 0x%x exceed the pool's %u queries", v.fn, query,
           *views, pass.viewMask, pool->count);
    return nullptr;
  }
  return pool;
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBeginQuery(VkCommandBuffer commandBuffer, VkQueryPool queryPool, uint32_t query,
                                              VkQueryControlFlags flags) {
  static constexpr QueryVuids kV{"vkCmdBeginQuery", "VUID-vkCmdBeginQuery-queryPool-parameter",
                                 "VUID-vkCmdBeginQuery-query-00802", "VUID-vkCmdBeginQuery-query-00808"};
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, kV.fn);
  if (!cb) return;
  uint32_t views = 1;
  QueryPool* pool = checkQuery(cb, queryPool, query, kV, &views);
  if (!pool) return;
  // VUID-vkCmdBeginQuery-queryType-02804 (timestamps are written, not begun), -04728 / -04729 (acceleration
  // structure property queries): vkrt's pools of other types are occlusion pools.
  if (pool->type != VK_QUERY_TYPE_OCCLUSION) {
    report(pool, Severity::Error,
           pool->type == VK_QUERY_TYPE_TIMESTAMP ? "VUID-vkCmdBeginQuery-queryType-02804"
                                                 : "VUID-vkCmdBeginQuery-queryType-04728",
           "%s: the pool's queryType %d cannot be begun", kV.fn, int(pool->type));
    return;
  }
  // VUID-vkCmdBeginQuery-queryType-00803: occlusion queries need a pool of a queue family with graphics
  if (!cb->supportsGraphics()) {
    report(cb, Severity::Error, "VUID-vkCmdBeginQuery-queryType-00803",
           "%s: an occlusion query in a command buffer of queue family %u, which has no graphics", kV.fn,
           cb->pool->queueFamilyIndex);
    return;
  }
  // VUID-vkCmdBeginQuery-queryType-00800: PRECISE needs the occlusionQueryPrecise feature
  if ((flags & VK_QUERY_CONTROL_PRECISE_BIT) && !cb->device->enabled(Feature::occlusionQueryPrecise)) {
    report(cb, Severity::Error, "VUID-vkCmdBeginQuery-queryType-00800",
           "%s: VK_QUERY_CONTROL_PRECISE_BIT without the occlusionQueryPrecise feature enabled", kV.fn);
    return;
  }
  DrawRecordState& rec = recordState(cb).draw;
  // VUID-vkCmdBeginQuery-queryPool-01922: one active query per type
  if (rec.occlusionPool) {
    report(cb, Severity::Error, "VUID-vkCmdBeginQuery-queryPool-01922",
           "%s: occlusion query %u of another or the same pool is still active (vkCmdEndQuery not recorded)", kV.fn,
           rec.occlusionQuery);
    return;
  }
  rec.occlusionPool = pool;
  rec.occlusionQuery = query;
  cb->record([pool, query, views](ExecState& st) {
    for (uint32_t v = 0; v < views; ++v) pool->begin(query + v);
    execState(st).draw.occlusion = pool->counter(query);
  });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdEndQuery(VkCommandBuffer commandBuffer, VkQueryPool queryPool, uint32_t query) {
  static constexpr QueryVuids kV{"vkCmdEndQuery", "VUID-vkCmdEndQuery-queryPool-parameter",
                                 "VUID-vkCmdEndQuery-query-00810", "VUID-vkCmdEndQuery-query-00812"};
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, kV.fn);
  if (!cb) return;
  uint32_t views = 1;
  QueryPool* pool = checkQuery(cb, queryPool, query, kV, &views);
  if (!pool) return;
  DrawRecordState& rec = recordState(cb).draw;
  // VUID-vkCmdEndQuery-None-01923: the query must be active
  if (rec.occlusionPool != pool || rec.occlusionQuery != query) {
    report(pool, Severity::Error, "VUID-vkCmdEndQuery-None-01923", "%s: query %u of this pool is not active", kV.fn,
           query);
    return;
  }
  rec.occlusionPool = nullptr;
  cb->record([pool, query, views](ExecState& st) {
    execState(st).draw.occlusion = nullptr;
    for (uint32_t v = 0; v < views; ++v) pool->end(query + v);
  });
}

}  // extern "C"
