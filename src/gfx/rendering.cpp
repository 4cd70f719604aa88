// vkCmdBeginRendering / vkCmdEndRendering (Vulkan 1.3 dynamic rendering) and vkCmdClearAttachments. A dynamic
// render pass instance is a PassInstance of one subpass (gfx/pass_exec.hpp): color attachments first, then their
// resolve views, then the depth/stencil view and its resolve views. RESUMING skips the load-op clears and SUSPENDING
// the resolves: a suspended and resumed instance is one instance whose pieces run in submission order.
#include <memory>

#include "gfx/graphics_state.hpp"
#include "gfx/pass_exec.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/format.hpp"
#include "runtime/image.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/image_view.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

using namespace vkrt;
using namespace vkrt::gfx;

namespace {

// Checks one VkRenderingAttachmentInfo with a view; `usage` is the attachment usage the view needs.
bool attachmentOk(CommandBuffer* cb, const VkRenderingAttachmentInfo& a, const ImageView* v, const char* what,
                  VkImageUsageFlags usage, const char* usageVuid, const char* fn) {
  if (!v) {
    report(cb, Severity::Error, "VUID-VkRenderingAttachmentInfo-imageView-parameter",
           "%s: %s imageView 0x%llx is not a live VkImageView", fn, what, (unsigned long long)rawHandle(a.imageView));
    return false;
  }
  // The view's usage (inherited from its image's aspects: stencilUsage for the stencil aspect)
  if (!(v->usage & usage)) {
    report(cb, Severity::Error, usageVuid, "%s: %s image view has usage 0x%x without 0x%x", fn, what, v->usage, usage);
    return false;
  }
  if (a.resolveMode == VK_RESOLVE_MODE_NONE) return true;
  const ImageView* r = fromHandle<ImageView>(a.resolveImageView);
  const bool integer =
      usage == VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT &&
      (formatInfo(v->format)->type == NumericType::UInt || formatInfo(v->format)->type == NumericType::SInt);
  // VUID-VkRenderingAttachmentInfo-imageView-06129/06130 (color modes), 06132 (multisampled), 06860 (a resolve
  // view), 06864 (single-sampled), 06865 (the same format)
  const char* vuid =
      usage == VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT && !integer && a.resolveMode != VK_RESOLVE_MODE_AVERAGE_BIT
          ? "VUID-VkRenderingAttachmentInfo-imageView-06129"
      : integer && a.resolveMode != VK_RESOLVE_MODE_SAMPLE_ZERO_BIT ? "VUID-VkRenderingAttachmentInfo-imageView-06130"
      : v->image->samples == 1                                      ? "VUID-VkRenderingAttachmentInfo-imageView-06132"
      : !r                                                          ? "VUID-VkRenderingAttachmentInfo-imageView-06860"
      : r->image->samples != 1                                      ? "VUID-VkRenderingAttachmentInfo-imageView-06864"
      : r->format != v->format                                      ? "VUID-VkRenderingAttachmentInfo-imageView-06865"
                                                                    : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid,
           "%s: %s resolves (mode 0x%x) a view of format %d with %u samples into %s (format %d, %u samples)", fn, what,
           a.resolveMode, (int)v->format, v->image->samples, r ? "a view" : "no view", r ? (int)r->format : 0,
           r ? r->image->samples : 0);
    return false;
  }
  return true;
}

void beginRendering(CommandBuffer* cb, const VkRenderingInfo& ri) {
  const char* fn = "vkCmdBeginRendering";
  Device* dev = cb->device;
  // VUID-vkCmdBeginRendering-dynamicRendering-06446
  if (!dev->enabled(Feature::dynamicRendering)) {
    report(cb, Severity::Error, "VUID-vkCmdBeginRendering-dynamicRendering-06446",
           "%s: the dynamicRendering feature is not enabled", fn);
    return;
  }
  // VUID-vkCmdBeginRendering-renderpass
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdBeginRendering-renderpass")) return;
  const VkPhysicalDeviceLimits& l = dev->physicalDevice->properties10.limits;
  const VkRect2D& ra = ri.renderArea;
  // VUID-vkCmdBeginRendering-commandBuffer-06068, VUID-VkRenderingInfo-viewMask-06069, multiview-06127, viewMask-06128,
  // renderArea-06071/06072/06073/06074, layerCount-07817, colorAttachmentCount-06106
  const char* vuid =
      cb->level == VK_COMMAND_BUFFER_LEVEL_SECONDARY && (ri.flags & VK_RENDERING_CONTENTS_SECONDARY_COMMAND_BUFFERS_BIT)
          ? "VUID-vkCmdBeginRendering-commandBuffer-06068"
      : ri.viewMask == 0 && ri.layerCount == 0                                 ? "VUID-VkRenderingInfo-viewMask-06069"
      : ri.viewMask != 0 && !dev->enabled(Feature::multiview)                  ? "VUID-VkRenderingInfo-multiview-06127"
      : ri.viewMask >> dev->physicalDevice->properties11.maxMultiviewViewCount ? "VUID-VkRenderingInfo-viewMask-06128"
      : ra.offset.x < 0                                                        ? "VUID-VkRenderingInfo-renderArea-06071"
      : ra.offset.y < 0                                                        ? "VUID-VkRenderingInfo-renderArea-06072"
      : uint64_t(ra.offset.x) + ra.extent.width > l.maxFramebufferWidth        ? "VUID-VkRenderingInfo-renderArea-06073"
      : uint64_t(ra.offset.y) + ra.extent.height > l.maxFramebufferHeight      ? "VUID-VkRenderingInfo-renderArea-06074"
      : ri.layerCount > l.maxFramebufferLayers                                 ? "VUID-VkRenderingInfo-layerCount-07817"
      : ri.colorAttachmentCount > l.maxColorAttachments ? "VUID-VkRenderingInfo-colorAttachmentCount-06106"
                                                        : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid,
           "%s: flags 0x%x, render area (%d, %d) %ux%u, layerCount %u, viewMask 0x%x, %u color attachments", fn,
           ri.flags, ra.offset.x, ra.offset.y, ra.extent.width, ra.extent.height, ri.layerCount, ri.viewMask,
           ri.colorAttachmentCount);
    return;
  }
  auto inst = std::make_shared<PassInstance>();
  inst->renderArea = ra;
  inst->layers = ri.viewMask ? 1 : ri.layerCount;
  PassSubpass sp;
  sp.colorCount = ri.colorAttachmentCount;
  sp.viewMask = ri.viewMask;
  const bool clears = !(ri.flags & VK_RENDERING_RESUMING_BIT);
  const bool resolves = !(ri.flags & VK_RENDERING_SUSPENDING_BIT);
  PassRecordState r;
  uint32_t samples = 0;
  // Adds a view as an attachment (checking that it covers the render area), returns its index.
  auto add = [&](const ImageView* v, const char* what) -> uint32_t {
    const VkExtent3D e = mipExtent(v->image->extent, v->range.baseMipLevel);
    // VUID-VkRenderingInfo-imageView-06075 / 06076: the render area inside every view
    if (uint64_t(ra.offset.x) + ra.extent.width > e.width || uint64_t(ra.offset.y) + ra.extent.height > e.height) {
      report(cb, Severity::Error,
             uint64_t(ra.offset.x) + ra.extent.width > e.width ? "VUID-VkRenderingInfo-imageView-06075"
                                                               : "VUID-VkRenderingInfo-imageView-06076",
             "%s: render area (%d, %d) %ux%u exceeds %s's %ux%u", fn, ra.offset.x, ra.offset.y, ra.extent.width,
             ra.extent.height, what, e.width, e.height);
      return VK_ATTACHMENT_UNUSED - 1;
    }
    inst->attachments.push_back(attachmentOf(*v));
    return uint32_t(inst->attachments.size() - 1);
  };
  constexpr uint32_t kFailed = VK_ATTACHMENT_UNUSED - 1;
  for (uint32_t c = 0; c < ri.colorAttachmentCount; ++c) {
    const VkRenderingAttachmentInfo& a = ri.pColorAttachments[c];
    sp.color[c] = VK_ATTACHMENT_UNUSED;
    r.colorFormats[c] = VK_FORMAT_UNDEFINED;
    if (!a.imageView) continue;
    const ImageView* v = fromHandle<ImageView>(a.imageView);
    if (!attachmentOk(cb, a, v, "a color attachment", VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                      "VUID-VkRenderingInfo-colorAttachmentCount-06087", fn))
      return;
    const uint32_t i = add(v, "a color attachment");
    if (i == kFailed) return;
    sp.color[c] = i;
    r.colorFormats[c] = v->format;
    samples = v->image->samples;
    if (clears && a.loadOp == VK_ATTACHMENT_LOAD_OP_CLEAR)
      sp.clears.push_back({i, VK_IMAGE_ASPECT_COLOR_BIT, a.clearValue});
    if (resolves && a.resolveMode != VK_RESOLVE_MODE_NONE) {
      const uint32_t d = add(fromHandle<ImageView>(a.resolveImageView), "a resolve attachment");
      if (d == kFailed) return;
      sp.resolves.push_back({i, d, VK_IMAGE_ASPECT_COLOR_BIT, a.resolveMode});
    }
  }
  const VkRenderingAttachmentInfo* da =
      ri.pDepthAttachment && ri.pDepthAttachment->imageView ? ri.pDepthAttachment : nullptr;
  const VkRenderingAttachmentInfo* sa =
      ri.pStencilAttachment && ri.pStencilAttachment->imageView ? ri.pStencilAttachment : nullptr;
  // VUID-VkRenderingInfo-pDepthAttachment-06085: one view for depth and stencil
  if (da && sa && da->imageView != sa->imageView) {
    report(cb, Severity::Error, "VUID-VkRenderingInfo-pDepthAttachment-06085",
           "%s: pDepthAttachment and pStencilAttachment name different image views", fn);
    return;
  }
  if (da || sa) {
    const ImageView* v = fromHandle<ImageView>((da ? da : sa)->imageView);
    if ((da && !attachmentOk(cb, *da, v, "the depth attachment", VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                             "VUID-VkRenderingInfo-pDepthAttachment-06088", fn)) ||
        (sa && !attachmentOk(cb, *sa, v, "the stencil attachment", VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                             "VUID-VkRenderingInfo-pStencilAttachment-06089", fn)))
      return;
    const VkImageAspectFlags aspects = formatAspects(v->format);
    // VUID-VkRenderingInfo-pDepthAttachment-06547 / pStencilAttachment-06548: formats with the aspect
    if ((da && !(aspects & VK_IMAGE_ASPECT_DEPTH_BIT)) || (sa && !(aspects & VK_IMAGE_ASPECT_STENCIL_BIT))) {
      report(cb, Severity::Error,
             da && !(aspects & VK_IMAGE_ASPECT_DEPTH_BIT) ? "VUID-VkRenderingInfo-pDepthAttachment-06547"
                                                          : "VUID-VkRenderingInfo-pStencilAttachment-06548",
             "%s: the depth/stencil view's format %d lacks the aspect it is attached for", fn, (int)v->format);
      return;
    }
    const uint32_t i = add(v, "the depth/stencil attachment");
    if (i == kFailed) return;
    sp.depthStencil = i;
    sp.depth = da != nullptr;
    sp.stencil = sa != nullptr;
    samples = samples ? samples : v->image->samples;
    VkImageAspectFlags clear = 0;
    if (clears && da && da->loadOp == VK_ATTACHMENT_LOAD_OP_CLEAR) clear |= VK_IMAGE_ASPECT_DEPTH_BIT;
    if (clears && sa && sa->loadOp == VK_ATTACHMENT_LOAD_OP_CLEAR) clear |= VK_IMAGE_ASPECT_STENCIL_BIT;
    if (clear) {
      VkClearValue value{};
      value.depthStencil.depth = da ? da->clearValue.depthStencil.depth : 0.0f;
      value.depthStencil.stencil = sa ? sa->clearValue.depthStencil.stencil : 0;
      sp.clears.push_back({i, clear, value});
    }
    const VkPhysicalDeviceVulkan12Properties& p12 = dev->physicalDevice->properties12;
    for (const VkRenderingAttachmentInfo* a : {da, sa}) {
      if (!a || a->resolveMode == VK_RESOLVE_MODE_NONE) continue;
      const bool depth = a == da;
      // VUID-VkRenderingInfo-pDepthAttachment-06102 / pStencilAttachment-06103: supported modes
      if (!((depth ? p12.supportedDepthResolveModes : p12.supportedStencilResolveModes) & a->resolveMode)) {
        report(cb, Severity::Error,
               depth ? "VUID-VkRenderingInfo-pDepthAttachment-06102" : "VUID-VkRenderingInfo-pStencilAttachment-06103",
               "%s: %s resolve mode 0x%x is not supported", fn, depth ? "depth" : "stencil", a->resolveMode);
        return;
      }
      if (!resolves) continue;
      const uint32_t d = add(fromHandle<ImageView>(a->resolveImageView), "a depth/stencil resolve attachment");
      if (d == kFailed) return;
      sp.resolves.push_back({i, d, depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_STENCIL_BIT, a->resolveMode});
    }
    r.depthFormat = da ? v->format : VK_FORMAT_UNDEFINED;
    r.stencilFormat = sa ? v->format : VK_FORMAT_UNDEFINED;
  }
  sp.samples = samples ? samples : 1;
  r.active = true;
  r.dynamicRendering = true;
  r.subpassCount = 1;
  r.colorCount = ri.colorAttachmentCount;
  r.hasDepth = sp.depth;
  r.hasStencil = sp.stencil;
  r.samples = sp.samples;
  r.viewMask = ri.viewMask;
  r.renderArea = ra;
  r.layers = inst->layers;
  inst->subpasses.push_back(std::move(sp));
  r.instance = inst;
  recordState(cb).pass = r;
  cb->insideRenderPass = true;
  cb->record([inst](ExecState& st) { beginSubpass(st, *inst, 0); });
}

// One VkClearAttachment over the rects, on the executing instance's target.
void clearOne(const raster::Target& t, const VkClearAttachment& c, const std::vector<VkClearRect>& rects) {
  auto each = [&](const raster::Surface& s, uint32_t texelBytes, uint32_t offset, uint32_t bytes, const uint8_t* v) {
    for (const VkClearRect& r : rects)
      fillSurface(s, texelBytes, offset, bytes, v, r.rect, r.baseArrayLayer, r.layerCount, t.viewMask);
  };
  uint8_t texel[16] = {};
  if (c.aspectMask & VK_IMAGE_ASPECT_COLOR_BIT) {
    if (c.colorAttachment >= t.colorCount || !t.color[c.colorAttachment].base) return;
    const raster::ColorFormat& f = t.colorFormat[c.colorAttachment];
    f.encode(f.format, c.clearValue.color.uint32, texel);
    each(t.color[c.colorAttachment], f.texelBytes, 0, f.texelBytes, texel);
    return;
  }
  const raster::DepthStencilTarget& ds = t.depthStencil;
  if ((c.aspectMask & VK_IMAGE_ASPECT_DEPTH_BIT) && ds.depthFormat != raster::DepthFormat::None) {
    const VkFormat f = ds.depthFormat == raster::DepthFormat::D16UNorm    ? VK_FORMAT_D16_UNORM
                       : ds.depthFormat == raster::DepthFormat::D32SFloat ? VK_FORMAT_D32_SFLOAT
                                                                          : VK_FORMAT_X8_D24_UNORM_PACK32;
    encodeDepth(f, c.clearValue.depthStencil.depth, texel);
    each(ds.depth, ds.depthTexelBytes, 0, aspectImageBytes(f, VK_IMAGE_ASPECT_DEPTH_BIT), texel);
  }
  if ((c.aspectMask & VK_IMAGE_ASPECT_STENCIL_BIT) && ds.stencilFormat != raster::StencilFormat::None) {
    texel[0] = uint8_t(c.clearValue.depthStencil.stencil);
    each(ds.stencil, ds.stencilTexelBytes, ds.stencilOffset, 1, texel);
  }
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBeginRendering(VkCommandBuffer commandBuffer,
                                                  const VkRenderingInfo* pRenderingInfo) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBeginRendering"))
    beginRendering(cb, *pRenderingInfo);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdEndRendering(VkCommandBuffer commandBuffer) {
  const char* fn = "vkCmdEndRendering";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  PassRecordState& r = recordState(cb).pass;
  // VUID-vkCmdEndRendering-renderpass, None-06161 (begun with vkCmdBeginRendering), commandBuffer-06162 (in this
  // command buffer)
  const char* vuid = !cb->insideRenderPass || !r.active ? "VUID-vkCmdEndRendering-renderpass"
                     : !r.dynamicRendering              ? "VUID-vkCmdEndRendering-None-06161"
                     : r.inherited                      ? "VUID-vkCmdEndRendering-commandBuffer-06162"
                                                        : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid, "%s: %s", fn,
           !r.active             ? "no render pass instance is active"
           : !r.dynamicRendering ? "the render pass instance was begun with vkCmdBeginRenderPass"
                                 : "the render pass instance was begun in another command buffer");
    return;
  }
  cb->record([inst = r.instance](ExecState& st) { endSubpass(st, *inst, 0, true); });
  r = PassRecordState{};
  cb->insideRenderPass = false;
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdClearAttachments(VkCommandBuffer commandBuffer, uint32_t attachmentCount,
                                                    const VkClearAttachment* pAttachments, uint32_t rectCount,
                                                    const VkClearRect* pRects) {
  const char* fn = "vkCmdClearAttachments";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  const PassRecordState& r = recordState(cb).pass;
  // VUID-vkCmdClearAttachments-renderpass
  if (!cb->insideRenderPass || !r.active) {
    report(cb, Severity::Error, "VUID-vkCmdClearAttachments-renderpass", "%s: no render pass instance is active", fn);
    return;
  }
  for (uint32_t i = 0; i < attachmentCount; ++i) {
    const VkClearAttachment& a = pAttachments[i];
    const VkImageAspectFlags ds = VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    // VUID-VkClearAttachment-aspectMask-requiredbitmask / 00019, VUID-vkCmdClearAttachments-aspectMask-07271
    const char* vuid = a.aspectMask == 0 ? "VUID-VkClearAttachment-aspectMask-requiredbitmask"
                       : (a.aspectMask & VK_IMAGE_ASPECT_COLOR_BIT) && (a.aspectMask & ds)
                           ? "VUID-VkClearAttachment-aspectMask-00019"
                       : (a.aspectMask & VK_IMAGE_ASPECT_COLOR_BIT) && a.colorAttachment >= r.colorCount
                           ? "VUID-vkCmdClearAttachments-aspectMask-07271"
                           : nullptr;
    if (vuid) {
      report(cb, Severity::Error, vuid,
             "%s: pAttachments[%u] has aspectMask 0x%x and colorAttachment %u (the subpass has %u color attachments)",
             fn, i, a.aspectMask, a.colorAttachment, r.colorCount);
      return;
    }
  }
  for (uint32_t i = 0; i < rectCount; ++i) {
    const VkClearRect& c = pRects[i];
    const VkRect2D& ra = r.renderArea;
    const bool knownArea = !r.inherited;  // a secondary does not know the render area nor the layers
    // VUID-vkCmdClearAttachments-layerCount-01934, pRects-00016 (inside the render area), pRects-06937 (the layers)
    const char* vuid =
        c.layerCount == 0 ? "VUID-vkCmdClearAttachments-layerCount-01934"
        : knownArea && (c.rect.offset.x < ra.offset.x || c.rect.offset.y < ra.offset.y ||
                        int64_t(c.rect.offset.x) + c.rect.extent.width > int64_t(ra.offset.x) + ra.extent.width ||
                        int64_t(c.rect.offset.y) + c.rect.extent.height > int64_t(ra.offset.y) + ra.extent.height)
            ? "VUID-vkCmdClearAttachments-pRects-00016"
        : knownArea && uint64_t(c.baseArrayLayer) + c.layerCount > r.layers ? "VUID-vkCmdClearAttachments-pRects-06937"
                                                                            : nullptr;
    if (vuid) {
      report(cb, Severity::Error, vuid,
             "%s: pRects[%u] (%d, %d) %ux%u, layers [%u, +%u) is not inside the render area (%d, %d) %ux%u and its %u "
             "layers",
             fn, i, c.rect.offset.x, c.rect.offset.y, c.rect.extent.width, c.rect.extent.height, c.baseArrayLayer,
             c.layerCount, ra.offset.x, ra.offset.y, ra.extent.width, ra.extent.height, r.layers);
      return;
    }
  }
  std::vector<VkClearAttachment> atts(pAttachments, pAttachments + attachmentCount);
  std::vector<VkClearRect> rects(pRects, pRects + rectCount);
  cb->record([atts = std::move(atts), rects = std::move(rects)](ExecState& st) {
    const PassExecState& pass = execState(st).pass;
    if (!pass.active) return;
    for (const VkClearAttachment& a : atts) clearOne(pass.target, a, rects);
  });
}

}  // extern "C"
