// VkFramebuffer: the image views of a render pass's attachments (or, imageless, what they will be:
// VkFramebufferAttachmentsCreateInfo), the framebuffer's extent and layer count.
#pragma once

#include <cstdint>
#include <vector>

#include "gfx/render_pass.hpp"
#include "runtime/object.hpp"

namespace vkrt {
class ImageView;
}

namespace vkrt::gfx {

// What an imageless framebuffer's attachment will be (VkFramebufferAttachmentImageInfo).
struct FramebufferImageInfo {
  VkImageCreateFlags flags = 0;
  VkImageUsageFlags usage = 0;
  uint32_t width = 0, height = 0, layerCount = 0;
  std::vector<VkFormat> viewFormats;
};

class Framebuffer : public Object {
 public:
  using Handle = VkFramebuffer;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_FRAMEBUFFER;

  Framebuffer(Device* dev, const VkFramebufferCreateInfo& info, RenderPass* pass);

  // The render pass it was created with, as far as compatibility goes (the render pass may be destroyed first).
  const std::vector<AttachmentDesc> passAttachments;
  const size_t passSubpassCount;
  const uint32_t width, height, layers;
  const bool imageless;
  std::vector<ImageView*> views;             // one per attachment; empty when imageless
  std::vector<FramebufferImageInfo> images;  // one per attachment when imageless
};

}  // namespace vkrt::gfx
