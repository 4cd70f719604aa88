// The draw part of the graphics state (gfx/graphics_state.hpp): graphics pipelines, dynamic state, vertex input.
//
// Dynamic state ("Pipeline Dynamic State"): a pipeline names the states it takes from the command buffer (DynBit
// bits of GraphicsPipeline::dynamicMask); the vkCmdSet* commands (gfx/dynamic_state.cpp) record their values into
// DrawExecState::dynamic when they execute, and at each draw resolveState() takes every dynamic state from there
// and the others from the pipeline. While recording, DrawRecordState tracks which states were set since they were
// last made undefined, for the draw-time checks (VUID-vkCmdDraw-commandBuffer-02701 and its kin).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "raster/raster.hpp"
#include "runtime/vk.hpp"

namespace vkrt {
class Buffer;
class QueryPool;
}  // namespace vkrt

namespace vkrt::gfx {

class GraphicsPipeline;
struct GraphicsPipelineDesc;

inline constexpr uint32_t kMaxVertexBindings = 32;
inline constexpr uint32_t kMaxVertexAttributes = 32;

// The dynamic states vkrt supports: Vulkan 1.0's, the ones 1.3 made core (extended dynamic state 1 and 2), and the
// logic op of VK_EXT_extended_dynamic_state2 (extendedDynamicState2LogicOp; not the patch control points: no
// tessellation).
enum DynBit : uint32_t {
  kDynViewport,
  kDynScissor,
  kDynLineWidth,
  kDynDepthBias,
  kDynBlendConstants,
  kDynDepthBounds,
  kDynStencilCompareMask,
  kDynStencilWriteMask,
  kDynStencilReference,
  kDynCullMode,
  kDynFrontFace,
  kDynTopology,
  kDynViewportWithCount,
  kDynScissorWithCount,
  kDynVertexStride,
  kDynDepthTestEnable,
  kDynDepthWriteEnable,
  kDynDepthCompareOp,
  kDynDepthBoundsTestEnable,
  kDynStencilTestEnable,
  kDynStencilOp,
  kDynRasterizerDiscardEnable,
  kDynDepthBiasEnable,
  kDynPrimitiveRestartEnable,
  kDynLogicOp,
  kDynCount
};

// The bit of a VkDynamicState; -1 for a state vkrt does not support.
int dynamicBit(VkDynamicState s);
// The state's name for reports ("VK_DYNAMIC_STATE_VIEWPORT").
const char* dynamicStateName(uint32_t bit);

struct VertexBufferBinding {
  const Buffer* buffer = nullptr;  // null: not bound (or VK_NULL_HANDLE)
  uint64_t offset = 0;
  uint64_t size = 0;    // bytes from offset (pSizes, or the rest of the buffer)
  uint32_t stride = 0;  // vkCmdBindVertexBuffers2's pStrides (used with kDynVertexStride)
};

// The draw executor's per-worker scratch (gfx/draw_executor.cpp), kept for the command buffer's later draws.
struct DrawScratch;
struct DrawScratchDeleter {
  void operator()(DrawScratch* s) const;
};

// While executing. The draw-time checks that depend on the bound pipeline run when the draw executes (the pipeline is
// bound by runtime's vkCmdBindPipeline, which this layer does not see while recording), against `dynamicSet`,
// `vertexBound` and `strideSet`, kept by the commands as they execute.
struct DrawExecState {
  raster::State dynamic;      // the values the vkCmdSet* commands set (the fields of dynamic states only)
  uint32_t scissorCount = 1;  // vkCmdSetScissorWithCount
  VertexBufferBinding vertex[kMaxVertexBindings];
  const Buffer* indexBuffer = nullptr;
  uint64_t indexOffset = 0;
  raster::IndexType indexType = raster::IndexType::None;

  // Validation state. Binding a pipeline makes the dynamic states it has static undefined ("Pipeline Dynamic
  // State"): a draw that finds a pipeline other than `lastPipeline` bound clears their bits first.
  const GraphicsPipeline* lastPipeline = nullptr;
  uint32_t dynamicSet = 0;   // DynBit bits of states set and not made undefined since
  uint32_t vertexBound = 0;  // bindings with a buffer bound (bit b = binding b)
  uint32_t strideSet = 0;    // bindings bound by vkCmdBindVertexBuffers2 with pStrides

  std::unique_ptr<DrawScratch, DrawScratchDeleter> scratch;  // made by the first draw

  // The active occlusion query's counter (vkCmdBeginQuery .. vkCmdEndQuery, gfx/query_commands.cpp): draws add the
  // samples that pass to it (raster::Draw::samplesPassed).
  std::atomic<uint64_t>* occlusion = nullptr;
};

// While recording (for validation).
struct DrawRecordState {
  bool indexBound = false;  // vkCmdBindIndexBuffer was recorded
  // The occlusion query begun and not yet ended in this command buffer (pool null: none).
  const QueryPool* occlusionPool = nullptr;
  uint32_t occlusionQuery = 0;
};

// The raster state of a draw: the pipeline's static state with every dynamic state of its dynamicMask taken from
// `dyn` (scissorCount: the dynamic scissor count, used when the scissors are dynamic with count).
void resolveState(const GraphicsPipelineDesc& pipeline, const DrawExecState& dyn, raster::State* out);

}  // namespace vkrt::gfx
