#include "gfx/framebuffer.hpp"

#include "gfx/render_pass.hpp"
#include "runtime/alloc.hpp"
#include "runtime/device.hpp"
#include "runtime/image.hpp"
#include "runtime/image_view.hpp"
#include "runtime/lookup.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt::gfx {

Framebuffer::Framebuffer(Device* dev, const VkFramebufferCreateInfo& info, RenderPass* pass)
    : Object(kType, dev->instance, dev),
      passAttachments(pass->attachments),
      passSubpassCount(pass->subpasses.size()),
      width(info.width),
      height(info.height),
      layers(info.layers),
      imageless(info.flags & VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT) {
  if (imageless) {
    auto* a = findInChain<VkFramebufferAttachmentsCreateInfo>(info.pNext,
                                                              VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO);
    for (uint32_t i = 0; a && i < a->attachmentImageInfoCount; ++i) {
      const VkFramebufferAttachmentImageInfo& ii = a->pAttachmentImageInfos[i];
      images.push_back({ii.flags, ii.usage, ii.width, ii.height, ii.layerCount,
                        std::vector<VkFormat>(ii.pViewFormats, ii.pViewFormats + ii.viewFormatCount)});
    }
  } else {
    for (uint32_t i = 0; i < info.attachmentCount; ++i) views.push_back(fromHandle<ImageView>(info.pAttachments[i]));
  }
}

}  // namespace vkrt::gfx

using namespace vkrt;
using namespace vkrt::gfx;

namespace {

// How attachment `a` of `pass` is used: as color/resolve/input, as depth/stencil.
void usesOf(const RenderPass& pass, uint32_t a, bool* color, bool* depthStencil) {
  *color = *depthStencil = false;
  for (const SubpassDesc& s : pass.subpasses) {
    for (uint32_t c : s.color) *color |= c == a;
    for (uint32_t c : s.resolve) *color |= c == a;
    *depthStencil |= s.depthStencil == a || s.depthStencilResolve == a;
  }
}

// Checks image view `v`, attachment `i` of a framebuffer for `pass` ("Framebuffers": VkFramebufferCreateInfo).
bool viewFits(Device* dev, const RenderPass& pass, const VkFramebufferCreateInfo& ci, uint32_t i, const ImageView* v) {
  const char* fn = "vkCreateFramebuffer";
  if (!v) {
    report(dev, Severity::Error, "VUID-VkFramebufferCreateInfo-flags-02778",
           "%s: pAttachments[%u] 0x%llx is not a live VkImageView", fn, i,
           (unsigned long long)rawHandle(ci.pAttachments[i]));
    return false;
  }
  const AttachmentDesc& a = pass.attachments[i];
  const VkExtent3D e = mipExtent(v->image->extent, v->range.baseMipLevel);
  bool color, ds;
  usesOf(pass, i, &color, &ds);
  const char* vuid =
      v->format != a.format                                        ? "VUID-VkFramebufferCreateInfo-pAttachments-00880"
      : v->image->samples != a.samples                             ? "VUID-VkFramebufferCreateInfo-pAttachments-00881"
      : v->range.levelCount != 1                                   ? "VUID-VkFramebufferCreateInfo-pAttachments-00883"
      : color && !(v->usage & VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) ? "VUID-VkFramebufferCreateInfo-pAttachments-00877"
      : ds && !(v->usage & VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)
          ? "VUID-VkFramebufferCreateInfo-pAttachments-02633"
      : e.width < ci.width                                   ? "VUID-VkFramebufferCreateInfo-flags-04533"
      : e.height < ci.height                                 ? "VUID-VkFramebufferCreateInfo-flags-04534"
      : !pass.multiview() && v->range.layerCount < ci.layers ? "VUID-VkFramebufferCreateInfo-flags-04535"
      // VUID-VkFramebufferCreateInfo-renderPass-04536: layers for every view
      : pass.used(i) && v->range.layerCount < pass.viewLayers() ? "VUID-VkFramebufferCreateInfo-renderPass-04536"
                                                                : nullptr;
  if (vuid) {
    report(dev, Severity::Error, vuid,
           "%s: pAttachments[%u] (format %d, %u samples, %u levels, view usage 0x%x, %ux%u, %u layers) does not fit "
           "attachment %u of the render pass (format %d, %u samples) in a %ux%u framebuffer of %u layers",
           fn, i, (int)v->format, v->image->samples, v->range.levelCount, v->usage, e.width, e.height,
           v->range.layerCount, i, (int)a.format, a.samples, ci.width, ci.height, ci.layers);
    return false;
  }
  return true;
}

}  // namespace

extern "C" {

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CreateFramebuffer(VkDevice device, const VkFramebufferCreateInfo* pCreateInfo,
                                                      const VkAllocationCallbacks* pAllocator,
                                                      VkFramebuffer* pFramebuffer) {
  Device* dev = fromHandleUnchecked<Device>(device);
  const VkFramebufferCreateInfo& ci = *pCreateInfo;
  const char* fn = "vkCreateFramebuffer";
  RenderPass* pass =
      liveOrReport<RenderPass>(dev, ci.renderPass, fn, "VUID-VkFramebufferCreateInfo-renderPass-parameter");
  if (!pass) return VK_ERROR_VALIDATION_FAILED_EXT;
  const VkPhysicalDeviceLimits& l = dev->physicalDevice->properties10.limits;
  // VUID-VkFramebufferCreateInfo-width-00885/00886, height-00887/00888, layers-00889/00890
  const char* vuid = ci.width == 0                         ? "VUID-VkFramebufferCreateInfo-width-00885"
                     : ci.width > l.maxFramebufferWidth    ? "VUID-VkFramebufferCreateInfo-width-00886"
                     : ci.height == 0                      ? "VUID-VkFramebufferCreateInfo-height-00887"
                     : ci.height > l.maxFramebufferHeight  ? "VUID-VkFramebufferCreateInfo-height-00888"
                     : ci.layers == 0                      ? "VUID-VkFramebufferCreateInfo-layers-00889"
                     : ci.layers > l.maxFramebufferLayers  ? "VUID-VkFramebufferCreateInfo-layers-00890"
                     : pass->multiview() && ci.layers != 1 ? "VUID-VkFramebufferCreateInfo-renderPass-02531"
                                                           : nullptr;
  if (vuid) {
    report(dev, Severity::Error, vuid, "%s: extent %ux%u with %u layers (limits %ux%u, %u layers; multiview: 1 layer)",
           fn, ci.width, ci.height, ci.layers, l.maxFramebufferWidth, l.maxFramebufferHeight, l.maxFramebufferLayers);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-VkFramebufferCreateInfo-attachmentCount-00876
  if (ci.attachmentCount != pass->attachments.size()) {
    report(dev, Severity::Error, "VUID-VkFramebufferCreateInfo-attachmentCount-00876",
           "%s: attachmentCount %u, but the render pass has %zu attachments", fn, ci.attachmentCount,
           pass->attachments.size());
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  if (ci.flags & VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT) {
    auto* a = findInChain<VkFramebufferAttachmentsCreateInfo>(ci.pNext,
                                                              VK_STRUCTURE_TYPE_FRAMEBUFFER_ATTACHMENTS_CREATE_INFO);
    // VUID-VkFramebufferCreateInfo-flags-03189 / 03190 / 03191
    const char* v = !dev->enabled(Feature::imagelessFramebuffer)        ? "VUID-VkFramebufferCreateInfo-flags-03189"
                    : !a                                                ? "VUID-VkFramebufferCreateInfo-flags-03190"
                    : a->attachmentImageInfoCount != ci.attachmentCount ? "VUID-VkFramebufferCreateInfo-flags-03191"
                                                                        : nullptr;
    if (v) {
      report(dev, Severity::Error, v,
             "%s: VK_FRAMEBUFFER_CREATE_IMAGELESS_BIT with imagelessFramebuffer %s and %s "
             "VkFramebufferAttachmentsCreateInfo (%u image infos for %u attachments)",
             fn, dev->enabled(Feature::imagelessFramebuffer) ? "enabled" : "not enabled", a ? "a" : "no",
             a ? a->attachmentImageInfoCount : 0, ci.attachmentCount);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    // VUID-VkFramebufferCreateInfo-renderPass-03198: with multiview, layers for every view
    for (uint32_t i = 0; i < ci.attachmentCount; ++i) {
      if (pass->used(i) && a->pAttachmentImageInfos[i].layerCount < pass->viewLayers()) {
        report(dev, Severity::Error, "VUID-VkFramebufferCreateInfo-renderPass-03198",
               "%s: pAttachmentImageInfos[%u].layerCount %u, but the render pass's view masks need %u layers", fn, i,
               a->pAttachmentImageInfos[i].layerCount, pass->viewLayers());
        return VK_ERROR_VALIDATION_FAILED_EXT;
      }
    }
  } else {
    for (uint32_t i = 0; i < ci.attachmentCount; ++i)
      if (!viewFits(dev, *pass, ci, i, fromHandle<ImageView>(ci.pAttachments[i])))
        return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  auto* fb = createObject<Framebuffer>(pAllocator, VK_SYSTEM_ALLOCATION_SCOPE_OBJECT, dev, ci, pass);
  if (!fb) return VK_ERROR_OUT_OF_HOST_MEMORY;
  *pFramebuffer = toHandle(fb);
  return VK_SUCCESS;
}

VKAPI_ATTR void VKAPI_CALL vkrt_DestroyFramebuffer(VkDevice device, VkFramebuffer framebuffer,
                                                   const VkAllocationCallbacks* pAllocator) {
  destroyDeviceChildWhenIdle<Framebuffer>(device, framebuffer, pAllocator, "vkDestroyFramebuffer",
                                          "VUID-vkDestroyFramebuffer-framebuffer-parameter",
                                          "VUID-vkDestroyFramebuffer-framebuffer-00892");
}

}  // extern "C"
