// A render pass instance as its commands execute it: built when vkCmdBeginRenderPass(2) / vkCmdBeginRendering is
// recorded (from the render pass and framebuffer, or the VkRenderingInfo), shared by the closures of the
// instance's commands. Everything here runs on the queue worker.
//
// Load operations ("Load Operations"): CLEAR writes the clear value into the render area of the views the first
// subpass using the attachment renders (its view mask's layers with multiview, else the framebuffer's layers), in
// every sample; LOAD and DONT_CARE and NONE leave the contents as they are. Store operations leave the contents
// (DONT_CARE keeps what was rendered, which the spec allows). Resolves run at the end of the subpass that names
// them, over the render area: color formats average the samples (float, normalized, sRGB in linear space) or take
// sample 0 (integers); depth/stencil with the resolve mode.
#pragma once

#include <cstdint>
#include <vector>

#include "gfx/pass_state.hpp"
#include "runtime/vk.hpp"

namespace vkrt {
class Image;
class ImageView;
struct ExecState;
}  // namespace vkrt

namespace vkrt::gfx {

// One attachment: an image view's image, format, mip level and layers.
struct PassAttachment {
  Image* image = nullptr;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t mip = 0, baseLayer = 0, layers = 1;
  VkImageLayout finalLayout = VK_IMAGE_LAYOUT_UNDEFINED;  // tracked for presentable images at the end
};

struct PassClear {
  uint32_t attachment;
  VkImageAspectFlags aspects;  // COLOR, or DEPTH and/or STENCIL
  VkClearValue value;
};

struct PassResolve {
  uint32_t src, dst;
  VkImageAspectFlags aspect;   // COLOR, DEPTH or STENCIL
  VkResolveModeFlagBits mode;  // AVERAGE for color (integers take sample 0)
};

struct PassSubpass {
  uint32_t colorCount = 0;
  uint32_t color[raster::kMaxColorAttachments];  // attachment indices or VK_ATTACHMENT_UNUSED
  uint32_t depthStencil = VK_ATTACHMENT_UNUSED;
  bool depth = false, stencil = false;  // which aspects of depthStencil the subpass uses
  uint32_t viewMask = 0;
  uint32_t samples = 1;
  std::vector<PassClear> clears;      // at the start of the subpass
  std::vector<PassResolve> resolves;  // at its end
};

struct PassInstance {
  std::vector<PassAttachment> attachments;
  std::vector<PassSubpass> subpasses;
  VkRect2D renderArea = {};
  uint32_t layers = 1;
};

PassAttachment attachmentOf(const ImageView& view);

// The rasterizer's target of subpass `s` (surfaces of the attachments' images at execution time).
raster::Target buildTarget(const PassInstance& p, uint32_t s);

// Starts subpass `s`: its load-op clears, then the target draws use (execState(st).pass).
void beginSubpass(ExecState& st, const PassInstance& p, uint32_t s);
// Ends subpass `s`: its resolves; after the last one the instance is inactive and presentable images take their
// final layouts.
void endSubpass(ExecState& st, const PassInstance& p, uint32_t s, bool last);

// Fills rect `r` of layers [baseLayer, +layerCount) (or, with viewMask, the layers of its views) of `surface`:
// `bytes` bytes of `texel` at byte `offset` of each sample's `texelBytes`-byte texel. The rect is clipped to the
// surface.
void fillSurface(const raster::Surface& surface, uint32_t texelBytes, uint32_t offset, uint32_t bytes,
                 const uint8_t* texel, const VkRect2D& r, uint32_t baseLayer, uint32_t layerCount, uint32_t viewMask);

}  // namespace vkrt::gfx
