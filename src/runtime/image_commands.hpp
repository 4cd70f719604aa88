// What the image transfer commands (runtime/image_commands.cpp, image_resolve.cpp) share: the VUID tables of one
// command and the checks of its images and regions, each reporting and returning false/nullptr on misuse.
#pragma once

#include <cstdint>

#include "runtime/vk.hpp"

namespace vkrt {

class CommandBuffer;
class Image;

// The VUIDs one command reports (they differ between the 1 and 2 versions of each command).
struct Vuids {
  const char* fn;
  const char* usage;   // image transfer usage
  const char* bound;   // image bound to memory
  const char* layout;  // image layout
  const char* mip;     // subresource mip level
  const char* layers;  // subresource layers
  const char* bounds;  // region inside the (mip of the) image
  const char* aspect;  // color aspect only
  // Buffer <-> image only:
  const char* bufUsage;
  const char* bufBound;
  const char* bufOffset;    // multiple of the texel size
  const char* bufSize;      // buffer large enough
  const char* rowLength;    // bufferRowLength >= width
  const char* imageHeight;  // bufferImageHeight >= height
};

// The transfer usage VUIDs of a command whose rules name the aspect (vkCmdCopyImage, vkCmdClearDepthStencilImage):
// with separate stencil usage (VkImageStencilUsageCreateInfo) the stencil aspect needs the bit in stencilUsage.
struct AspectUsageVuids {
  const char* stencil;          // the stencil aspect, image without separate stencil usage (nullptr: Vuids::usage)
  const char* separateStencil;  // the stencil aspect, image with separate stencil usage
  const char* separateOther;    // the other aspects, image with separate stencil usage
};

// A live image bound to memory, with the transfer usage and a transfer layout; reports otherwise. `aspects`: those
// the command accesses. Without `av` the command's rule (Vuids::usage) asks the image's usage for every aspect, and
// the stencil aspect also needs stencilUsage ("Image Creation": the stencil aspect is used only as stencilUsage
// says); with `av` each aspect needs its own usage only.
Image* transferImage(CommandBuffer* cb, VkImage h, bool dst, VkImageLayout layout, const Vuids& v,
                     VkImageAspectFlags aspects = 0, const AspectUsageVuids* av = nullptr);
// Checks that the aspects (a non-empty subset of the image's), mip level and layers of `sub` exist in the image.
bool subresourceInImage(const Image& img, const VkImageSubresourceLayers& sub, uint32_t index, const char* what,
                        const Vuids& v);
// Checks that [offset, offset + extent) of (mip, layers) lies inside the image.
bool regionInImage(const Image& img, const VkImageSubresourceLayers& sub, VkOffset3D off, VkExtent3D ext,
                   uint32_t index, const char* what, const Vuids& v);

}  // namespace vkrt
