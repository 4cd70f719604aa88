// Texel copies and clears on vkrt images: plain functions with no Vulkan object state, run by the image
// transfer commands (runtime/image_commands.cpp) on the queue worker, and unit-tested on their own.
#pragma once

#include <cstdint>

#include "runtime/image.hpp"

namespace vkrt {

// Bytes a buffer must hold past bufferOffset for region `r` of an image with `texelSize`-byte texels.
VkDeviceSize bufferFootprint(const VkBufferImageCopy2& r, uint32_t texelSize);

// Copies one region between `buffer` (the bound memory of the buffer, offset 0) and `image`.
void copyBufferImage(const Image& image, uint8_t* buffer, const VkBufferImageCopy2& r, bool toImage);

// Copies one region between two images with the same texel size; the depth slices of a 3D image pair with
// the layers of a 1D/2D image.
void copyImageImage(const Image& src, const Image& dst, const VkImageCopy2& r);

// Encodes a clear color for `format` into `texel` (texelSize bytes). Returns false for unknown formats.
bool encodeClearColor(const FormatInfo& format, const VkClearColorValue& color, uint8_t* texel);

// Fills the subresources of `range` (VK_REMAINING_* allowed) with the encoded texel.
void clearImage(const Image& image, const uint8_t* texel, const VkImageSubresourceRange& range);

// IEEE-style unsigned/signed small floats: 16-bit half (sign, 5-bit exponent, 10-bit mantissa) and the
// unsigned 11/10-bit floats of B10G11R11, rounded to nearest even.
uint16_t floatToHalf(float f);
uint32_t floatToUnsignedSmallFloat(float f, int mantissaBits);

}  // namespace vkrt
