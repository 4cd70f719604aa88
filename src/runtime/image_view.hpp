// VkImageView: an image's subresource range, format and swizzle, kept for image descriptors.
#pragma once

#include "runtime/object.hpp"
#include "runtime/quad_sampling.hpp"

namespace vkrt {

class Image;

class ImageView : public Object {
 public:
  using Handle = VkImageView;
  static constexpr VkObjectType kType = VK_OBJECT_TYPE_IMAGE_VIEW;

  ImageView(Device* dev, const VkImageViewCreateInfo& info, Image* image);

  Image* const image;
  const VkImageViewType viewType;
  const VkFormat format;
  const VkComponentMapping components;
  const VkImageSubresourceRange range;  // VK_REMAINING_* resolved
  // The view's usage ("Image Views", inherited usage): VkImageViewUsageCreateInfo::usage, else the image's usage of
  // the view's aspects (stencilUsage for a stencil-only view, the intersection for depth + stencil).
  const VkImageUsageFlags usage;
  // What the quad sampler's vector path reads (quad_sampling.hpp), resolved at creation.
  QuadView quad;
};

}  // namespace vkrt
