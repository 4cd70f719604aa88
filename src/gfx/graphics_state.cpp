#include "gfx/graphics_state.hpp"

namespace vkrt::gfx {

GraphicsExecState& execState(ExecState& st) {
  if (!st.graphicsState) st.graphicsState = std::make_unique<GraphicsExecState>();
  return static_cast<GraphicsExecState&>(*st.graphicsState);
}

GraphicsRecordState& recordState(CommandBuffer* cb) {
  if (!cb->graphicsRecording) {
    auto s = std::make_unique<GraphicsRecordState>();
    initPassRecordState(cb, s->pass);  // a secondary's inherited render pass instance
    cb->graphicsRecording = std::move(s);
  }
  return static_cast<GraphicsRecordState&>(*cb->graphicsRecording);
}

}  // namespace vkrt::gfx
