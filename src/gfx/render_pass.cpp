#include "gfx/render_pass.hpp"

#include <algorithm>

#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/format.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {

RenderPass::RenderPass(Device* dev, std::vector<AttachmentDesc> a, std::vector<SubpassDesc> s, uint32_t deps)
    : Object(kType, dev->instance, dev), attachments(std::move(a)), subpasses(std::move(s)), dependencyCount(deps) {}

bool compatible(const RenderPass& a, const std::vector<AttachmentDesc>& b, size_t bSubpassCount) {
  if (a.attachments.size() != b.size() || a.subpasses.size() != bSubpassCount) return false;
  for (size_t i = 0; i < b.size(); ++i)
    if (a.attachments[i].format != b[i].format || a.attachments[i].samples != b[i].samples) return false;
  return true;
}

}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

namespace {

// The VUIDs that differ between vkCreateRenderPass and vkCreateRenderPass2.
struct PassVuids {
  const char* fn;
  const char* index;        // attachment index in range
  const char* colorFormat;  // COLOR_ATTACHMENT feature
  const char* resolveFormat;
  const char* dsFormat;      // DEPTH_STENCIL_ATTACHMENT feature
  const char* colorSamples;  // color attachments' sample counts equal
  const char* dsSamples;     // depth/stencil sample count equals the color one
  const char* resolveFrom1;  // a resolve's color attachment is multisampled
  const char* resolveTo1;    // a resolve attachment is single-sampled
  const char* resolveSame;   // a resolve attachment has its color attachment's format
  const char* preserveUnused;
};
constexpr PassVuids kV1{"vkCreateRenderPass",
                        "VUID-VkRenderPassCreateInfo-attachment-00834",
                        "VUID-VkSubpassDescription-pColorAttachments-02648",
                        "VUID-VkSubpassDescription-pResolveAttachments-02649",
                        "VUID-VkSubpassDescription-pDepthStencilAttachment-02650",
                        "VUID-VkSubpassDescription-pColorAttachments-06868",
                        "VUID-VkSubpassDescription-pDepthStencilAttachment-01418",
                        "VUID-VkSubpassDescription-pResolveAttachments-00848",
                        "VUID-VkSubpassDescription-pResolveAttachments-00849",
                        "VUID-VkSubpassDescription-pResolveAttachments-00850",
                        "VUID-VkSubpassDescription-attachment-00853"};
constexpr PassVuids kV2{"vkCreateRenderPass2",
                        "VUID-VkRenderPassCreateInfo2-attachment-03051",
                        "VUID-VkSubpassDescription2-pColorAttachments-02898",
                        "VUID-VkSubpassDescription2-pResolveAttachments-02899",
                        "VUID-VkSubpassDescription2-pDepthStencilAttachment-02900",
                        "VUID-VkSubpassDescription2-multisampledRenderToSingleSampled-06872",
                        "VUID-VkSubpassDescription2-multisampledRenderToSingleSampled-06872",
                        "VUID-VkSubpassDescription2-pResolveAttachments-03066",
                        "VUID-VkSubpassDescription2-pResolveAttachments-03067",
                        "VUID-VkSubpassDescription2-pResolveAttachments-03068",
                        "VUID-VkSubpassDescription2-attachment-03073"};

std::vector<uint32_t> indices(const VkAttachmentReference2* refs, uint32_t count) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; refs && i < count; ++i) out.push_back(refs[i].attachment);
  return out;
}

// Checks the subpasses of `ci` and builds the render pass; reports and returns an error code on misuse.
VkResult createPass(Device* dev, const VkRenderPassCreateInfo2& ci, const PassVuids& v,
                    const VkAllocationCallbacks* pAllocator, VkRenderPass* pRenderPass) {
  const uint32_t n = ci.attachmentCount;
  std::vector<AttachmentDesc> atts(n);
  for (uint32_t i = 0; i < n; ++i) {
    const VkAttachmentDescription2& a = ci.pAttachments[i];
    atts[i] = {a.format,  uint32_t(a.samples), a.loadOp,        a.stencilLoadOp,
               a.storeOp, a.stencilStoreOp,    a.initialLayout, a.finalLayout};
  }
  // VUID-VkRenderPassCreateInfo2-viewMask-03058: view masks all zero or all non-zero
  for (uint32_t s = 1; s < ci.subpassCount; ++s) {
    if ((ci.pSubpasses[s].viewMask == 0) != (ci.pSubpasses[0].viewMask == 0)) {
      report(dev, Severity::Error, "VUID-VkRenderPassCreateInfo2-viewMask-03058",
             "%s: subpass %u has view mask 0x%x, subpass 0 0x%x (all zero or all non-zero)", v.fn, s,
             ci.pSubpasses[s].viewMask, ci.pSubpasses[0].viewMask);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  // VUID-VkSubpassDescription2-multiview-06558 / VkRenderPassMultiviewCreateInfo-multiview-06555: view masks need
  // the multiview feature
  if (ci.subpassCount && ci.pSubpasses[0].viewMask && !dev->enabled(Feature::multiview)) {
    report(dev, Severity::Error,
           v.fn == kV1.fn ? "VUID-VkRenderPassMultiviewCreateInfo-multiview-06555"
                          : "VUID-VkSubpassDescription2-multiview-06558",
           "%s: subpass 0 has view mask 0x%x, but the multiview feature is not enabled", v.fn,
           ci.pSubpasses[0].viewMask);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkSubpassDescription2-viewMask-06706 / VkRenderPassMultiviewCreateInfo-pViewMasks-06697: every view
  // index below maxMultiviewViewCount
  const uint32_t maxViews = dev->physicalDevice->properties11.maxMultiviewViewCount;
  for (uint32_t s = 0; s < ci.subpassCount; ++s) {
    if (ci.pSubpasses[s].viewMask >> maxViews) {
      report(dev, Severity::Error,
             v.fn == kV1.fn ? "VUID-VkRenderPassMultiviewCreateInfo-pViewMasks-06697"
                            : "VUID-VkSubpassDescription2-viewMask-06706",
             "%s: subpass %u has view mask 0x%x (maxMultiviewViewCount %u)", v.fn, s, ci.pSubpasses[s].viewMask,
             maxViews);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
  }
  std::vector<SubpassDesc> subs(ci.subpassCount);
  for (uint32_t s = 0; s < ci.subpassCount; ++s) {
    const VkSubpassDescription2& d = ci.pSubpasses[s];
    SubpassDesc& out = subs[s];
    out.color = indices(d.pColorAttachments, d.colorAttachmentCount);
    if (d.pResolveAttachments) out.resolve = indices(d.pResolveAttachments, d.colorAttachmentCount);
    out.input = indices(d.pInputAttachments, d.inputAttachmentCount);
    out.preserve.assign(d.pPreserveAttachments, d.pPreserveAttachments + d.preserveAttachmentCount);
    if (d.pDepthStencilAttachment) out.depthStencil = d.pDepthStencilAttachment->attachment;
    out.viewMask = d.viewMask;
    if (auto* r = findInChain<VkSubpassDescriptionDepthStencilResolve>(
            d.pNext, VK_STRUCTURE_TYPE_SUBPASS_DESCRIPTION_DEPTH_STENCIL_RESOLVE);
        r && r->pDepthStencilResolveAttachment) {
      out.depthStencilResolve = r->pDepthStencilResolveAttachment->attachment;
      out.depthResolveMode = r->depthResolveMode;
      out.stencilResolveMode = r->stencilResolveMode;
    }
    // Every index in range (VUID-VkRenderPassCreateInfo(2)-attachment-00834/03051); preserve ones not UNUSED
    // (VUID-VkSubpassDescription-attachment-00853, VkSubpassDescription2-attachment-03073).
    auto inRange = [&](uint32_t a, const char* what) {
      if (a == VK_ATTACHMENT_UNUSED || a < n) return true;
      report(dev, Severity::Error, v.index, "%s: subpass %u: %s attachment %u, but the render pass has %u", v.fn, s,
             what, a, n);
      return false;
    };
    for (uint32_t a : out.color)
      if (!inRange(a, "color")) return VK_ERROR_VALIDATION_FAILED_EXT;
    for (uint32_t a : out.resolve)
      if (!inRange(a, "resolve")) return VK_ERROR_VALIDATION_FAILED_EXT;
    for (uint32_t a : out.input)
      if (!inRange(a, "input")) return VK_ERROR_VALIDATION_FAILED_EXT;
    if (!inRange(out.depthStencil, "depth/stencil") || !inRange(out.depthStencilResolve, "depth/stencil resolve"))
      return VK_ERROR_VALIDATION_FAILED_EXT;
    for (uint32_t a : out.preserve) {
      if (a == VK_ATTACHMENT_UNUSED) {
        report(dev, Severity::Error, v.preserveUnused, "%s: subpass %u preserves VK_ATTACHMENT_UNUSED", v.fn, s);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      if (!inRange(a, "preserve")) return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // Formats with the attachment features (VUID-VkSubpassDescription(2)-pColorAttachments-02648/02898,
    // pResolveAttachments-02649/02899, pDepthStencilAttachment-02650/02900).
    uint32_t samples = 0;
    for (size_t c = 0; c < out.color.size(); ++c) {
      const uint32_t a = out.color[c];
      if (a == VK_ATTACHMENT_UNUSED) continue;
      if (!(formatFeatures(atts[a].format) & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT)) {
        report(dev, Severity::Error, v.colorFormat,
               "%s: subpass %u color attachment %zu (attachment %u) has format %d, which lacks "
               "VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT",
               v.fn, s, c, a, (int)atts[a].format);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      // VUID-VkSubpassDescription-pColorAttachments-06868: one sample count for the color attachments
      if (samples && atts[a].samples != samples) {
        report(dev, Severity::Error, v.colorSamples,
               "%s: subpass %u color attachment %zu has %u samples, an earlier one %u", v.fn, s, c, atts[a].samples,
               samples);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      samples = atts[a].samples;
      const uint32_t r = out.resolve.empty() ? VK_ATTACHMENT_UNUSED : out.resolve[c];
      if (r == VK_ATTACHMENT_UNUSED) continue;
      const char* vuid = atts[a].samples == 1                                                         ? v.resolveFrom1
                         : atts[r].samples != 1                                                       ? v.resolveTo1
                         : atts[r].format != atts[a].format                                           ? v.resolveSame
                         : !(formatFeatures(atts[r].format) & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT) ? v.resolveFormat
                                                                                                      : nullptr;
      if (vuid) {
        report(dev, Severity::Error, vuid,
               "%s: subpass %u resolves color attachment %u (format %d, %u samples) into attachment %u (format %d, "
               "%u samples): a multisampled attachment into a single-sampled one of the same color format",
               v.fn, s, a, (int)atts[a].format, atts[a].samples, r, (int)atts[r].format, atts[r].samples);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    if (out.depthStencil != VK_ATTACHMENT_UNUSED) {
      const AttachmentDesc& ds = atts[out.depthStencil];
      if (!(formatFeatures(ds.format) & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)) {
        report(dev, Severity::Error, v.dsFormat,
               "%s: subpass %u depth/stencil attachment %u has format %d, which lacks "
               "VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT",
               v.fn, s, out.depthStencil, (int)ds.format);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      // VUID-VkSubpassDescription-pDepthStencilAttachment-01418: the color attachments' sample count
      if (samples && ds.samples != samples) {
        report(dev, Severity::Error, v.dsSamples,
               "%s: subpass %u depth/stencil attachment has %u samples, its color attachments %u", v.fn, s, ds.samples,
               samples);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
      samples = ds.samples;
    }
    out.samples = samples ? samples : 1;
    // VkSubpassDescriptionDepthStencilResolve (Vulkan 1.2): a multisampled depth/stencil attachment into a
    // single-sampled one of the same format, with supported modes (VkPhysicalDeviceDepthStencilResolveProperties)
    if (out.depthStencilResolve != VK_ATTACHMENT_UNUSED) {
      const VkPhysicalDeviceVulkan12Properties& p12 = dev->physicalDevice->properties12;
      const uint32_t r = out.depthStencilResolve;
      const uint32_t ds = out.depthStencil;
      const VkImageAspectFlags aspects = formatAspects(atts[r].format);
      const char* vuid =
          ds == VK_ATTACHMENT_UNUSED
              ? "VUID-VkSubpassDescriptionDepthStencilResolve-pDepthStencilResolveAttachment-03177"
          : atts[ds].samples == 1 ? "VUID-VkSubpassDescriptionDepthStencilResolve-pDepthStencilResolveAttachment-03179"
          : atts[r].samples != 1  ? "VUID-VkSubpassDescriptionDepthStencilResolve-pDepthStencilResolveAttachment-03180"
          : !(formatFeatures(atts[r].format) & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)
              ? "VUID-VkSubpassDescriptionDepthStencilResolve-pDepthStencilResolveAttachment-02651"
          : out.depthResolveMode == VK_RESOLVE_MODE_NONE && out.stencilResolveMode == VK_RESOLVE_MODE_NONE
              ? "VUID-VkSubpassDescriptionDepthStencilResolve-pDepthStencilResolveAttachment-03178"
          : (aspects & VK_IMAGE_ASPECT_DEPTH_BIT) && out.depthResolveMode &&
                  !(p12.supportedDepthResolveModes & out.depthResolveMode)
              ? "VUID-VkSubpassDescriptionDepthStencilResolve-depthResolveMode-03183"
          : (aspects & VK_IMAGE_ASPECT_STENCIL_BIT) && out.stencilResolveMode &&
                  !(p12.supportedStencilResolveModes & out.stencilResolveMode)
              ? "VUID-VkSubpassDescriptionDepthStencilResolve-stencilResolveMode-03184"
              : nullptr;
      if (vuid) {
        report(dev, Severity::Error, vuid,
               "%s: subpass %u resolves depth/stencil attachment %u into attachment %u (format %d, %u samples) with "
               "depth mode 0x%x and stencil mode 0x%x",
               v.fn, s, ds, r, (int)atts[r].format, atts[r].samples, out.depthResolveMode, out.stencilResolveMode);
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
    // First and last uses (input and preserve attachments count as uses; preserve ones are not "used" for load ops).
    auto use = [&](uint32_t a) {
      if (a == VK_ATTACHMENT_UNUSED) return;
      if (atts[a].firstUse == VK_ATTACHMENT_UNUSED) atts[a].firstUse = s;
      atts[a].lastUse = s;
    };
    for (uint32_t a : out.color) use(a);
    for (uint32_t a : out.resolve) use(a);
    for (uint32_t a : out.input) use(a);
    use(out.depthStencil);
    use(out.depthStencilResolve);
  }
  auto* rp = createObject<RenderPass>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, std::move(atts),
                                      std::move(subs), ci.dependencyCount);
  if (!rp) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pRenderPass = toHandle(rp);
  return VK_SUCCESS;
}

VkAttachmentReference2 ref2(const VkAttachmentReference& r, VkImageAspectFlags aspect) {
  return {VK_STRUCTURE_TYPE_ATTACHMENT_REFERENCE_2, nullptr, r.attachment, r.layout, aspect};
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateRenderPass2(VkDevice device, const VkRenderPassCreateInfo2* pCreateInfo,
                                                      const VkAllocationCallbacks* pAllocator,
                                                      VkRenderPass* pRenderPass) {
  return createPass(fromHandleUnchecked<Device>(device), *pCreateInfo, kV2, pAllocator, pRenderPass);
}

// vkCreateRenderPass: converted to the VkRenderPassCreateInfo2 form ("Render Pass Creation": the 1.0 structures
// map member by member; VkRenderPassMultiviewCreateInfo gives the subpasses' view masks).
VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateRenderPass(VkDevice device, const VkRenderPassCreateInfo* pCreateInfo,
                                                     const VkAllocationCallbacks* pAllocator,
                                                     VkRenderPass* pRenderPass) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkRenderPassCreateInfo& ci = *pCreateInfo;
  auto* mv =
      findInChain<VkRenderPassMultiviewCreateInfo>(ci.pNext, VK_STRUCTURE_TYPE_RENDER_PASS_MULTIVIEW_CREATE_INFO);
  // VUID-VkRenderPassCreateInfo-pNext-01928: a view mask per subpass, if any
  if (mv && mv->subpassCount && mv->subpassCount != ci.subpassCount) {
    report(dev, Severity::Error, "VUID-VkRenderPassCreateInfo-pNext-01928",
           "vkCreateRenderPass: VkRenderPassMultiviewCreateInfo has %u view masks for %u subpasses", mv->subpassCount,
           ci.subpassCount);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  std::vector<VkAttachmentDescription2> atts;
  for (uint32_t i = 0; i < ci.attachmentCount; ++i) {
    const VkAttachmentDescription& a = ci.pAttachments[i];
    atts.push_back({VK_STRUCTURE_TYPE_ATTACHMENT_DESCRIPTION_2, nullptr, a.flags, a.format, a.samples, a.loadOp,
                    a.storeOp, a.stencilLoadOp, a.stencilStoreOp, a.initialLayout, a.finalLayout});
  }
  std::vector<std::vector<VkAttachmentReference2>> refs;  // per subpass: color, resolve, input, depth/stencil
  refs.reserve(ci.subpassCount * 4);
  std::vector<VkSubpassDescription2> subs;
  for (uint32_t s = 0; s < ci.subpassCount; ++s) {
    const VkSubpassDescription& d = ci.pSubpasses[s];
    auto list = [&](const VkAttachmentReference* r, uint32_t count, VkImageAspectFlags aspect) {
      refs.emplace_back();
      for (uint32_t i = 0; r && i < count; ++i) refs.back().push_back(ref2(r[i], aspect));
      return r ? refs.back().data() : nullptr;
    };
    VkSubpassDescription2 d2{VK_STRUCTURE_TYPE_SUBPASS_DESCRIPTION_2};
    d2.flags = d.flags;
    d2.pipelineBindPoint = d.pipelineBindPoint;
    d2.viewMask = mv && mv->subpassCount ? mv->pViewMasks[s] : 0;
    d2.inputAttachmentCount = d.inputAttachmentCount;
    d2.pInputAttachments = list(d.pInputAttachments, d.inputAttachmentCount, VK_IMAGE_ASPECT_COLOR_BIT);
    d2.colorAttachmentCount = d.colorAttachmentCount;
    d2.pColorAttachments = list(d.pColorAttachments, d.colorAttachmentCount, 0);
    d2.pResolveAttachments = list(d.pResolveAttachments, d.colorAttachmentCount, 0);
    d2.pDepthStencilAttachment = list(d.pDepthStencilAttachment, 1, 0);
    d2.preserveAttachmentCount = d.preserveAttachmentCount;
    d2.pPreserveAttachments = d.pPreserveAttachments;
    subs.push_back(d2);
  }
  VkRenderPassCreateInfo2 ci2{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO_2};
  ci2.flags = ci.flags;
  ci2.attachmentCount = ci.attachmentCount;
  ci2.pAttachments = atts.data();
  ci2.subpassCount = ci.subpassCount;
  ci2.pSubpasses = subs.data();
  ci2.dependencyCount = ci.dependencyCount;
  return createPass(dev, ci2, kV1, pAllocator, pRenderPass);
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyRenderPass(VkDevice device, VkRenderPass renderPass,
                                                  const VkAllocationCallbacks* pAllocator) {
  // A recorded command buffer keeps what it needs of the render pass (gfx/pass_exec.hpp PassInstance): no wait.
  destroyDeviceChild<RenderPass>(device, renderPass, pAllocator, "vkDestroyRenderPass",
                                 "VUID-vkDestroyRenderPass-renderPass-parameter");
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetRenderAreaGranularity(VkDevice, VkRenderPass, VkExtent2D* pGranularity) {
  *pGranularity = {1, 1};  // any render area is as fast as any other
}

}  // extern "C"
