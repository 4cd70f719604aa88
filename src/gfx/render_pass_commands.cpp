// vkCmdBeginRenderPass(2), vkCmdNextSubpass(2), vkCmdEndRenderPass(2): each validates (reporting the VUID and
// recording nothing on misuse), keeps the record-time state (gfx::recordState(cb).pass) and records a closure that
// runs the instance (gfx/pass_exec.hpp). Also the inherited state of secondary command buffers.
#include <memory>

#include "gfx/framebuffer.hpp"
#include "gfx/graphics_state.hpp"
#include "gfx/pass_exec.hpp"
#include "gfx/render_pass.hpp"
#include "runtime/alloc.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/format.hpp"
#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "runtime/lookup.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {

// The record state of subpass `s` of a render pass.
static void enterSubpass(PassRecordState& r, const RenderPass& rp, uint32_t s) {
  const SubpassDesc& d = rp.subpasses[s];
  r.subpass = s;
  r.colorCount = uint32_t(d.color.size());
  for (uint32_t c = 0; c < raster::kMaxColorAttachments; ++c)
    r.colorFormats[c] = c < d.color.size() && d.color[c] != VK_ATTACHMENT_UNUSED ? rp.attachments[d.color[c]].format
                                                                                 : VK_FORMAT_UNDEFINED;
  const VkFormat ds =
      d.depthStencil != VK_ATTACHMENT_UNUSED ? rp.attachments[d.depthStencil].format : VK_FORMAT_UNDEFINED;
  r.hasDepth = formatAspects(ds) & VK_IMAGE_ASPECT_DEPTH_BIT;
  r.hasStencil = formatAspects(ds) & VK_IMAGE_ASPECT_STENCIL_BIT;
  r.depthFormat = r.hasDepth ? ds : VK_FORMAT_UNDEFINED;
  r.stencilFormat = r.hasStencil ? ds : VK_FORMAT_UNDEFINED;
  r.samples = d.samples;
  r.viewMask = d.viewMask;
}

void initPassRecordState(CommandBuffer* cb, PassRecordState& s) {
  const CommandBuffer::Inheritance& inh = cb->inheritance;
  if (!inh.continues) return;
  s.active = true;
  s.inherited = true;
  if (inh.renderPass) {
    auto* rp = fromHandle<RenderPass>(inh.renderPass);
    if (!rp || inh.subpass >= rp->subpasses.size()) return;
    s.renderPass = rp;
    s.subpassCount = uint32_t(rp->subpasses.size());
    enterSubpass(s, *rp, inh.subpass);
    return;
  }
  s.dynamicRendering = true;
  s.subpassCount = 1;
  s.colorCount = uint32_t(inh.colorFormats.size());
  for (uint32_t c = 0; c < s.colorCount && c < raster::kMaxColorAttachments; ++c)
    s.colorFormats[c] = inh.colorFormats[c];
  s.depthFormat = inh.depthFormat;
  s.stencilFormat = inh.stencilFormat;
  s.hasDepth = inh.depthFormat != VK_FORMAT_UNDEFINED;
  s.hasStencil = inh.stencilFormat != VK_FORMAT_UNDEFINED;
  s.viewMask = inh.viewMask;
  s.samples = uint32_t(inh.samples);
}

}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

namespace {

// The image views of the instance: the framebuffer's, or VkRenderPassAttachmentBeginInfo's for an imageless one
// (checked against the framebuffer's image infos and the render pass). Empty on misuse (reported).
bool instanceViews(CommandBuffer* cb, const VkRenderPassBeginInfo& bi, const RenderPass& rp, const Framebuffer& fb,
                   const char* fn, std::vector<const ImageView*>* out) {
  auto* ab =
      findInChain<VkRenderPassAttachmentBeginInfo>(bi.pNext, VK_STRUCTURE_TYPE_RENDER_PASS_ATTACHMENT_BEGIN_INFO);
  if (!fb.imageless) {
    // VUID-VkRenderPassBeginInfo-framebuffer-03207: attachments at begin only for imageless framebuffers
    if (ab && ab->attachmentCount) {
      report(cb, Severity::Error, "VUID-VkRenderPassBeginInfo-framebuffer-03207",
             "%s: VkRenderPassAttachmentBeginInfo gives %u attachments, but the framebuffer is not imageless", fn,
             ab->attachmentCount);
      return false;
    }
    out->assign(fb.views.begin(), fb.views.end());
    for (const ImageView* v : *out)
      if (!v) {
        report(cb, Severity::Error, "VUID-VkRenderPassBeginInfo-framebuffer-parameter",
               "%s: an image view of the framebuffer was destroyed", fn);
        return false;
      }
    return true;
  }
  // VUID-VkRenderPassBeginInfo-framebuffer-03208: one view per attachment
  if (!ab || ab->attachmentCount != fb.images.size()) {
    report(cb, Severity::Error, "VUID-VkRenderPassBeginInfo-framebuffer-03208",
           "%s: the framebuffer is imageless and has %zu attachments; VkRenderPassAttachmentBeginInfo gives %u", fn,
           fb.images.size(), ab ? ab->attachmentCount : 0);
    return false;
  }
  for (uint32_t i = 0; i < ab->attachmentCount; ++i) {
    const ImageView* v = fromHandle<ImageView>(ab->pAttachments[i]);
    if (!v) {
      report(cb, Severity::Error, "VUID-VkRenderPassAttachmentBeginInfo-pAttachments-parameter",
             "%s: VkRenderPassAttachmentBeginInfo::pAttachments[%u] is not a live VkImageView", fn, i);
      return false;
    }
    const FramebufferImageInfo& ii = fb.images[i];
    const VkExtent3D e = mipExtent(v->image->extent, v->range.baseMipLevel);
    // VUID-VkRenderPassBeginInfo-framebuffer-04627 (the view's inherited usage), 03211 / 03212 (width, height), 03213
    // (layers), 03216 (format), 03217 (samples)
    const char* vuid = v->usage != ii.usage                             ? "VUID-VkRenderPassBeginInfo-framebuffer-04627"
                       : e.width != ii.width                            ? "VUID-VkRenderPassBeginInfo-framebuffer-03211"
                       : e.height != ii.height                          ? "VUID-VkRenderPassBeginInfo-framebuffer-03212"
                       : v->range.layerCount != ii.layerCount           ? "VUID-VkRenderPassBeginInfo-framebuffer-03213"
                       : v->format != rp.attachments[i].format          ? "VUID-VkRenderPassBeginInfo-framebuffer-03216"
                       : v->image->samples != rp.attachments[i].samples ? "VUID-VkRenderPassBeginInfo-framebuffer-03217"
                                                                        : nullptr;
    if (vuid) {
      report(cb, Severity::Error, vuid,
             "%s: attachment %u (usage 0x%x, %ux%u, %u layers, format %d, %u samples) does not match the framebuffer's "
             "image info (usage 0x%x, %ux%u, %u layers) and the render pass (format %d, %u samples)",
             fn, i, v->usage, e.width, e.height, v->range.layerCount, (int)v->format, v->image->samples, ii.usage,
             ii.width, ii.height, ii.layerCount, (int)rp.attachments[i].format, rp.attachments[i].samples);
      return false;
    }
    out->push_back(v);
  }
  return true;
}

// The subpasses of the instance: targets, load-op clears at first use, resolves.
void buildSubpasses(const RenderPass& rp, const VkRenderPassBeginInfo& bi, PassInstance* inst) {
  for (uint32_t s = 0; s < rp.subpasses.size(); ++s) {
    const SubpassDesc& d = rp.subpasses[s];
    PassSubpass sp;
    sp.colorCount = uint32_t(d.color.size());
    for (uint32_t c = 0; c < sp.colorCount; ++c) sp.color[c] = d.color[c];
    sp.depthStencil = d.depthStencil;
    if (d.depthStencil != VK_ATTACHMENT_UNUSED) {
      const VkImageAspectFlags a = formatAspects(rp.attachments[d.depthStencil].format);
      sp.depth = a & VK_IMAGE_ASPECT_DEPTH_BIT;
      sp.stencil = a & VK_IMAGE_ASPECT_STENCIL_BIT;
    }
    sp.viewMask = d.viewMask;
    sp.samples = d.samples;
    for (uint32_t i = 0; i < rp.attachments.size(); ++i) {
      const AttachmentDesc& a = rp.attachments[i];
      if (a.firstUse != s) continue;
      const VkImageAspectFlags aspects = formatAspects(a.format);
      VkImageAspectFlags clear = 0;
      if (a.loadOp == VK_ATTACHMENT_LOAD_OP_CLEAR)
        clear |= aspects & (VK_IMAGE_ASPECT_COLOR_BIT | VK_IMAGE_ASPECT_DEPTH_BIT);
      if (a.stencilLoadOp == VK_ATTACHMENT_LOAD_OP_CLEAR) clear |= aspects & VK_IMAGE_ASPECT_STENCIL_BIT;
      if (clear) sp.clears.push_back({i, clear, bi.pClearValues[i]});
    }
    for (size_t c = 0; c < d.resolve.size(); ++c)
      if (d.resolve[c] != VK_ATTACHMENT_UNUSED && d.color[c] != VK_ATTACHMENT_UNUSED)
        sp.resolves.push_back({d.color[c], d.resolve[c], VK_IMAGE_ASPECT_COLOR_BIT, VK_RESOLVE_MODE_AVERAGE_BIT});
    if (d.depthStencilResolve != VK_ATTACHMENT_UNUSED) {
      const VkImageAspectFlags a = formatAspects(rp.attachments[d.depthStencilResolve].format);
      if ((a & VK_IMAGE_ASPECT_DEPTH_BIT) && d.depthResolveMode)
        sp.resolves.push_back({d.depthStencil, d.depthStencilResolve, VK_IMAGE_ASPECT_DEPTH_BIT, d.depthResolveMode});
      if ((a & VK_IMAGE_ASPECT_STENCIL_BIT) && d.stencilResolveMode)
        sp.resolves.push_back(
            {d.depthStencil, d.depthStencilResolve, VK_IMAGE_ASPECT_STENCIL_BIT, d.stencilResolveMode});
    }
    inst->subpasses.push_back(std::move(sp));
  }
}

void beginRenderPass(CommandBuffer* cb, const VkRenderPassBeginInfo& bi, bool two) {
  const char* fn = two ? "vkCmdBeginRenderPass2" : "vkCmdBeginRenderPass";
  // VUID-vkCmdBeginRenderPass(2)-bufferlevel
  if (cb->level != VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
    report(cb, Severity::Error,
           two ? "VUID-vkCmdBeginRenderPass2-bufferlevel" : "VUID-vkCmdBeginRenderPass-bufferlevel",
           "%s: commandBuffer is a secondary command buffer", fn);
    return;
  }
  // VUID-vkCmdBeginRenderPass(2)-renderpass
  if (!cb->outsideRenderPass(fn,
                             two ? "VUID-vkCmdBeginRenderPass2-renderpass" : "VUID-vkCmdBeginRenderPass-renderpass"))
    return;
  RenderPass* rp = liveOrReport<RenderPass>(cb, bi.renderPass, fn, "VUID-VkRenderPassBeginInfo-renderPass-parameter");
  Framebuffer* fb =
      rp ? liveOrReport<Framebuffer>(cb, bi.framebuffer, fn, "VUID-VkRenderPassBeginInfo-framebuffer-parameter")
         : nullptr;
  if (!fb) return;
  // VUID-VkRenderPassBeginInfo-renderPass-00904
  if (!compatible(*rp, fb->passAttachments, fb->passSubpassCount)) {
    report(cb, Severity::Error, "VUID-VkRenderPassBeginInfo-renderPass-00904",
           "%s: the render pass (%zu attachments, %zu subpasses) is not compatible with the framebuffer's (%zu "
           "attachments, %zu subpasses; formats and sample counts must match)",
           fn, rp->attachments.size(), rp->subpasses.size(), fb->passAttachments.size(), fb->passSubpassCount);
    return;
  }
  // VUID-VkRenderPassBeginInfo-pNext-02850/02851/02852/02853: the render area inside the framebuffer
  const VkRect2D& ra = bi.renderArea;
  const char* vuid = ra.offset.x < 0                                         ? "VUID-VkRenderPassBeginInfo-pNext-02850"
                     : ra.offset.y < 0                                       ? "VUID-VkRenderPassBeginInfo-pNext-02851"
                     : uint64_t(ra.offset.x) + ra.extent.width > fb->width   ? "VUID-VkRenderPassBeginInfo-pNext-02852"
                     : uint64_t(ra.offset.y) + ra.extent.height > fb->height ? "VUID-VkRenderPassBeginInfo-pNext-02853"
                                                                             : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid, "%s: render area (%d, %d) %ux%u is not inside the %ux%u framebuffer", fn,
           ra.offset.x, ra.offset.y, ra.extent.width, ra.extent.height, fb->width, fb->height);
    return;
  }
  // VUID-VkRenderPassBeginInfo-clearValueCount-00902: a clear value for every attachment that is cleared
  for (uint32_t i = 0; i < rp->attachments.size(); ++i) {
    const AttachmentDesc& a = rp->attachments[i];
    const bool clears =
        a.loadOp == VK_ATTACHMENT_LOAD_OP_CLEAR ||
        ((formatAspects(a.format) & VK_IMAGE_ASPECT_STENCIL_BIT) && a.stencilLoadOp == VK_ATTACHMENT_LOAD_OP_CLEAR);
    if (clears && (i >= bi.clearValueCount || !bi.pClearValues)) {
      report(cb, Severity::Error, "VUID-VkRenderPassBeginInfo-clearValueCount-00902",
             "%s: attachment %u is cleared by its load op, but clearValueCount is %u", fn, i, bi.clearValueCount);
      return;
    }
  }
  std::vector<const ImageView*> views;
  if (!instanceViews(cb, bi, *rp, *fb, fn, &views)) return;
  auto inst = std::make_shared<PassInstance>();
  for (uint32_t i = 0; i < views.size(); ++i) {
    PassAttachment a = attachmentOf(*views[i]);
    a.finalLayout = rp->attachments[i].finalLayout;
    inst->attachments.push_back(a);
  }
  inst->renderArea = ra;
  inst->layers = fb->layers;
  buildSubpasses(*rp, bi, inst.get());

  PassRecordState& r = recordState(cb).pass;
  r = PassRecordState{};
  r.active = true;
  r.renderPass = rp;
  r.subpassCount = uint32_t(rp->subpasses.size());
  r.renderArea = ra;
  r.layers = fb->layers;
  r.instance = inst;
  enterSubpass(r, *rp, 0);
  cb->insideRenderPass = true;
  cb->record([inst](ExecState& st) { beginSubpass(st, *inst, 0); });
}

void nextSubpass(CommandBuffer* cb, bool two) {
  const char* fn = two ? "vkCmdNextSubpass2" : "vkCmdNextSubpass";
  // VUID-vkCmdNextSubpass(2)-bufferlevel
  if (cb->level != VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
    report(cb, Severity::Error, two ? "VUID-vkCmdNextSubpass2-bufferlevel" : "VUID-vkCmdNextSubpass-bufferlevel",
           "%s: commandBuffer is a secondary command buffer", fn);
    return;
  }
  PassRecordState& r = recordState(cb).pass;
  // VUID-vkCmdNextSubpass(2)-renderpass
  if (!cb->insideRenderPass || !r.active) {
    report(cb, Severity::Error, two ? "VUID-vkCmdNextSubpass2-renderpass" : "VUID-vkCmdNextSubpass-renderpass",
           "%s: no render pass instance is active", fn);
    return;
  }
  // VUID-vkCmdNextSubpass(2)-None-00909/03102: not past the last subpass (one subpass with dynamic rendering)
  if (r.dynamicRendering || r.subpass + 1 >= r.subpassCount) {
    report(cb, Severity::Error, two ? "VUID-vkCmdNextSubpass2-None-03102" : "VUID-vkCmdNextSubpass-None-00909",
           "%s: subpass %u is the last of %u", fn, r.subpass, r.dynamicRendering ? 1 : r.subpassCount);
    return;
  }
  const uint32_t s = r.subpass;
  enterSubpass(r, *r.renderPass, s + 1);
  cb->record([inst = r.instance, s](ExecState& st) {
    endSubpass(st, *inst, s, false);
    beginSubpass(st, *inst, s + 1);
  });
}

void endRenderPass(CommandBuffer* cb, bool two) {
  const char* fn = two ? "vkCmdEndRenderPass2" : "vkCmdEndRenderPass";
  // VUID-vkCmdEndRenderPass(2)-bufferlevel
  if (cb->level != VK_COMMAND_BUFFER_LEVEL_PRIMARY) {
    report(cb, Severity::Error, two ? "VUID-vkCmdEndRenderPass2-bufferlevel" : "VUID-vkCmdEndRenderPass-bufferlevel",
           "%s: commandBuffer is a secondary command buffer", fn);
    return;
  }
  PassRecordState& r = recordState(cb).pass;
  // VUID-vkCmdEndRenderPass(2)-renderpass, None-06170 / 06171 (not begun with vkCmdBeginRendering), None-00910 /
  // 03103 (the last subpass)
  const char* vuid = !cb->insideRenderPass || !r.active
                         ? (two ? "VUID-vkCmdEndRenderPass2-renderpass" : "VUID-vkCmdEndRenderPass-renderpass")
                     : r.dynamicRendering
                         ? (two ? "VUID-vkCmdEndRenderPass2-None-06171" : "VUID-vkCmdEndRenderPass-None-06170")
                     : r.subpass + 1 != r.subpassCount
                         ? (two ? "VUID-vkCmdEndRenderPass2-None-03103" : "VUID-vkCmdEndRenderPass-None-00910")
                         : nullptr;
  if (vuid) {
    report(cb, Severity::Error, vuid, "%s: %s (subpass %u of %u)", fn,
           !r.active            ? "no render pass instance is active"
           : r.dynamicRendering ? "the render pass instance was begun with vkCmdBeginRendering"
                                : "the current subpass is not the last",
           r.subpass, r.subpassCount);
    return;
  }
  const uint32_t s = r.subpass;
  cb->record([inst = r.instance, s](ExecState& st) { endSubpass(st, *inst, s, true); });
  r = PassRecordState{};
  cb->insideRenderPass = false;
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBeginRenderPass(VkCommandBuffer commandBuffer,
                                                   const VkRenderPassBeginInfo* pRenderPassBegin, VkSubpassContents) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBeginRenderPass"))
    beginRenderPass(cb, *pRenderPassBegin, false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBeginRenderPass2(VkCommandBuffer commandBuffer,
                                                    const VkRenderPassBeginInfo* pRenderPassBegin,
                                                    const VkSubpassBeginInfo*) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdBeginRenderPass2"))
    beginRenderPass(cb, *pRenderPassBegin, true);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdNextSubpass(VkCommandBuffer commandBuffer, VkSubpassContents) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdNextSubpass")) nextSubpass(cb, false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdNextSubpass2(VkCommandBuffer commandBuffer, const VkSubpassBeginInfo*,
                                                const VkSubpassEndInfo*) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdNextSubpass2")) nextSubpass(cb, true);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdEndRenderPass(VkCommandBuffer commandBuffer) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdEndRenderPass")) endRenderPass(cb, false);
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdEndRenderPass2(VkCommandBuffer commandBuffer, const VkSubpassEndInfo*) {
  if (CommandBuffer* cb = CommandBuffer::recording(commandBuffer, "vkCmdEndRenderPass2")) endRenderPass(cb, true);
}

}  // extern "C"
