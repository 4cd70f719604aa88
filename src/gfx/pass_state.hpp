// The render pass instance part of the graphics state (gfx/graphics_state.hpp): render passes, framebuffers,
// dynamic rendering, clears and resolves.
#pragma once

#include <cstdint>

#include "raster/raster.hpp"

namespace vkrt::gfx {

// While executing: the render pass instance, if any. Draws render into `target` (the current subpass's
// attachments, the render area, samples and view mask).
struct PassExecState {
  bool active = false;
  raster::Target target;
};

// While recording: what the validation of later commands needs.
struct PassRecordState {
  bool active = false;
  uint32_t subpass = 0;
  uint32_t colorCount = 0;  // of the current subpass
  bool hasDepth = false, hasStencil = false;
  uint32_t samples = 1;
  uint32_t viewMask = 0;
};

}  // namespace vkrt::gfx
