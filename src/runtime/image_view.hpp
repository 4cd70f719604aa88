// VkImageView: an image's subresource range, format and swizzle, kept for image descriptors.
#pragma once

#include "abi/abi.hpp"
#include "runtime/object.hpp"
#include "runtime/quad_sampling.hpp"

namespace vkrt {

class Image;
struct FormatInfo;

// A view as the storage image fast path reads it (vkrt_image_write and vkrt_image_read, image_functions.cpp): a 2D
// view of a one-sample 2D image, its base level and layer, in one of the commonest storage formats; `kind` None for
// every other view (and where the image has no memory when the view is created): the generic path then decides on
// every call. The fast path's bytes and words are the generic path's (encodeTexel, decodeTexel).
struct StoreView {
  enum class Kind : uint8_t {
    None,
    Unorm8,      // R8G8B8A8_UNORM
    Unorm8Bgra,  // B8G8R8A8_UNORM
    Words,       // `words` 32-bit components (SFLOAT, UINT or SINT), stored as given
  };
  Kind kind = Kind::None;
  const FormatInfo* format = nullptr;  // the view's (decodeTexel and encodeTexel where the fast path has no code)
  uint8_t words = 0;                   // Words: 1 to 4
  bool integer = false;                // Words: UINT or SINT (a read's missing alpha is 1, else 1.0)
  // Where the texels are: base (texel (0, 0) of the view's base level and layer), pitch and extent, and the kind
  // again as compiled code reads it (abi.hpp: every image view descriptor's record points here; kind 0 for None).
  abi::ImageTexels texels{};
};

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
  // What the storage image fast path reads, resolved at creation (describeStoreView, image_functions.cpp).
  StoreView store;
};

StoreView describeStoreView(const ImageView& view);

}  // namespace vkrt
