// The draw part of the graphics state (gfx/graphics_state.hpp): graphics pipelines, dynamic state, vertex input.
#pragma once

#include <cstdint>

#include "raster/raster.hpp"

namespace vkrt::gfx {

struct DrawExecState {};

struct DrawRecordState {};

}  // namespace vkrt::gfx
