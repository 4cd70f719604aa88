// What a command buffer carries for graphics: while it records (for validation: the render pass instance being
// recorded, the bound graphics pipeline) and while it executes (the render pass instance as the rasterizer's target,
// the pipeline's and the dynamic state, vertex and index buffers). Kept in runtime's LayerState slots
// (CommandBuffer::graphicsRecording, ExecState::graphicsState), created on first use.
//
// Two parts with two owners: PassState (gfx/pass_state.hpp: render passes, framebuffers, dynamic rendering, clears
// and resolves) and DrawState (gfx/draw_state.hpp: graphics pipelines, dynamic state, vertex input, draws).
#pragma once

#include "gfx/draw_state.hpp"
#include "gfx/pass_state.hpp"
#include "runtime/command_buffer.hpp"

namespace vkrt::gfx {

struct GraphicsExecState : LayerState {
  PassExecState pass;
  DrawExecState draw;
};

struct GraphicsRecordState : LayerState {
  PassRecordState pass;
  DrawRecordState draw;
};

// The command buffer's graphics state while it executes / records (created on first use).
GraphicsExecState& execState(ExecState& st);
GraphicsRecordState& recordState(CommandBuffer* cb);

}  // namespace vkrt::gfx
