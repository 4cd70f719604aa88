// The render pass instance part of the graphics state (gfx/graphics_state.hpp): render passes, framebuffers,
// dynamic rendering, clears and resolves.
#pragma once

#include <cstdint>
#include <memory>

#include "raster/raster.hpp"
#include "runtime/vk.hpp"

namespace vkrt {
class CommandBuffer;
}

namespace vkrt::gfx {

class RenderPass;
struct PassInstance;  // gfx/pass_exec.hpp

// While executing: the render pass instance, if any. Draws render into `target` (the current subpass's
// attachments, the render area, samples and view mask). Surfaces address the attachments' image views: base is
// the view's first layer at its mip level; a combined depth/stencil format gives both surfaces the same base and
// texel size, and the rasterizer adds `stencilOffset` (3 for D24_UNORM_S8_UINT, 4 for D32_SFLOAT_S8_UINT) to reach
// the stencil byte. A secondary command buffer executed inside the instance sees the same state
// (vkCmdExecuteCommands hands it over).
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
  // The current subpass's formats (VK_FORMAT_UNDEFINED for an unused attachment / no depth or stencil).
  VkFormat colorFormats[raster::kMaxColorAttachments] = {};
  VkFormat depthFormat = VK_FORMAT_UNDEFINED, stencilFormat = VK_FORMAT_UNDEFINED;
  bool dynamicRendering =
      false;               // begun with vkCmdBeginRendering (or inherited VkCommandBufferInheritanceRenderingInfo)
  bool inherited = false;  // a secondary command buffer that continues a render pass instance
  const RenderPass* renderPass = nullptr;  // the instance's render pass (null with dynamic rendering)
  uint32_t subpassCount = 0;
  VkRect2D renderArea = {};                // unknown (0x0) in a secondary
  uint32_t layers = 1;                     // framebuffer layers / VkRenderingInfo::layerCount
  std::shared_ptr<PassInstance> instance;  // what the instance's commands execute with; null in a secondary
};

// Fills a secondary command buffer's state from its VkCommandBufferInheritanceInfo (CommandBuffer::inheritance):
// called when its graphics recording state is created (gfx/graphics_state.cpp).
void initPassRecordState(CommandBuffer* cb, PassRecordState& s);

}  // namespace vkrt::gfx
