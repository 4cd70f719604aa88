// VkRenderPass: attachments, subpasses and what the commands of a render pass instance need from them, kept in
// the VkRenderPassCreateInfo2 form (vkCreateRenderPass's structures are converted: multiview masks from
// VkRenderPassMultiviewCreateInfo, input attachment aspects from VkRenderPassInputAttachmentAspectCreateInfo).
//
// Per attachment, the subpass that uses it first and last ("Render Pass Load/Store Operations": a CLEAR load op
// applies at the first subpass that uses the attachment, within the render area; store ops at the last). Input
// attachments are recorded (they count as uses) but shaders cannot read them yet. Dependencies are only counted:
// a render pass instance executes its subpasses in order on one thread, which satisfies every dependency.
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/object.hpp"

namespace vkrt::gfx {

struct AttachmentDesc {
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t samples = 1;
  VkAttachmentLoadOp loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE, stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  VkAttachmentStoreOp storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE, stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  VkImageLayout initialLayout = VK_IMAGE_LAYOUT_UNDEFINED, finalLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  uint32_t firstUse = VK_ATTACHMENT_UNUSED;  // subpass index, UNUSED if no subpass uses it
  uint32_t lastUse = VK_ATTACHMENT_UNUSED;
};

struct SubpassDesc {
  std::vector<uint32_t> color;    // attachment indices or VK_ATTACHMENT_UNUSED
  std::vector<uint32_t> resolve;  // empty or one per color attachment
  std::vector<uint32_t> input;
  std::vector<uint32_t> preserve;
  uint32_t depthStencil = VK_ATTACHMENT_UNUSED;
  uint32_t depthStencilResolve = VK_ATTACHMENT_UNUSED;
  VkResolveModeFlagBits depthResolveMode = VK_RESOLVE_MODE_NONE, stencilResolveMode = VK_RESOLVE_MODE_NONE;
  uint32_t viewMask = 0;
  uint32_t samples = 1;  // of its color and depth/stencil attachments (1 if none)
};

class RenderPass : public Object {
 public:
  using Handle = VkRenderPass;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_RENDER_PASS;

  RenderPass(Device* dev, std::vector<AttachmentDesc> attachments, std::vector<SubpassDesc> subpasses,
             uint32_t dependencyCount);

  const std::vector<AttachmentDesc> attachments;
  const std::vector<SubpassDesc> subpasses;
  const uint32_t dependencyCount;
  bool multiview() const { return subpasses[0].viewMask != 0; }
  // The layers an attachment needs with multiview: one more than the highest view index of any subpass (0 without).
  uint32_t viewLayers() const {
    uint32_t m = 0;
    for (const SubpassDesc& s : subpasses) m |= s.viewMask;
    return m ? 32 - uint32_t(__builtin_clz(m)) : 0;
  }
  // Whether attachment `a` is a color, resolve, input or depth/stencil (resolve) attachment of any subpass.
  bool used(uint32_t a) const {
    for (const SubpassDesc& s : subpasses) {
      for (const auto* list : {&s.color, &s.resolve, &s.input})
        for (uint32_t x : *list)
          if (x == a) return true;
      if (s.depthStencil == a || s.depthStencilResolve == a) return true;
    }
    return false;
  }
};

// Render pass compatibility ("Render Pass Compatibility"), as far as framebuffers and secondary command buffers
// need it: the same attachment count, formats and sample counts, and the same subpass count.
bool compatible(const RenderPass& a, const std::vector<AttachmentDesc>& bAttachments, size_t bSubpassCount);

}  // namespace vkrt::gfx
