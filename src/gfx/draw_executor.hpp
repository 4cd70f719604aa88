// Running a draw (gfx/draw_executor.cpp): at execution, the bound graphics pipeline's state merged with the dynamic
// state (resolveState), the render pass instance's target, the descriptor sets resolved as compute dispatches do
// (runtime/bound_resources.hpp), and the shaders run as the rasterizer's vertex and fragment stages under the
// compute path's supervision (exec/supervise.hpp: watchdog, fault recovery, reported like a compute shader's).
#pragma once

#include <cstdint>

#include "runtime/command_buffer.hpp"

namespace vkrt::gfx {

struct DrawParams {
  uint32_t count = 0;  // vertices, or indices when `indexed`
  uint32_t instanceCount = 1;
  uint32_t firstVertex = 0;  // non-indexed
  uint32_t firstIndex = 0;   // indexed
  int32_t vertexOffset = 0;  // indexed
  uint32_t firstInstance = 0;
  uint32_t drawIndex = 0;  // DrawIndex: the draw's index in an indirect (count) command
  bool indexed = false;
};

// Runs one draw with the state bound when it executes, after the draw-time checks that depend on the bound pipeline
// (each reported against `cb` with the VUID of `command`, the draw then skipped). `cb` names reports.
void executeDraw(const CommandBuffer* cb, ExecState& st, const DrawParams& params, const char* command);

}  // namespace vkrt::gfx
