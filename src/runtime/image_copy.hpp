// Texel copies and clears on vkrt images: plain functions with no Vulkan object state, run by the image
// transfer commands (runtime/image_commands.cpp) on the queue worker, and unit-tested on their own.
#pragma once

#include <cstdint>

#include "runtime/image.hpp"

namespace vkrt {

// Bytes a buffer must hold past bufferOffset for region `r` of an image with `texelSize`-byte texels, or blocks of
// `block` x `block` texels and `texelSize` bytes for a compressed format.
VkDeviceSize bufferFootprint(const VkBufferImageCopy2& r, uint32_t texelSize, uint32_t block = 1);

// Region `r` of a compressed image (4x4 blocks: block 4) in blocks: offsets divided by the block, extents and
// bufferRowLength / bufferImageHeight rounded up to whole blocks ("Buffer and Image Addressing": a partial block at
// the edge of a mip level is copied whole). The identity for block 1.
VkBufferImageCopy2 regionInBlocks(const VkBufferImageCopy2& r, uint32_t block);

// Copies one region between `buffer` (the bound memory of the buffer, offset 0) and `image`, for the region's
// aspect: a depth or stencil aspect is packed in the buffer as the spec's "Depth/Stencil Formats" say
// (aspectBufferTexelSize: D24 depth in 32 bits, stencil in bytes) and written into the image without touching the
// other aspect (aspectImageBytes).
void copyBufferImage(const Image& image, uint8_t* buffer, const VkBufferImageCopy2& r, bool toImage);

// Copies one region between two images with the same texel size (all samples of each pixel; with one aspect of a
// combined depth/stencil format, only that aspect's bytes); the depth slices of a 3D image pair with
// the layers of a 1D/2D image. A compressed side is copied in whole blocks: its offset is in texels, the region's
// extent in the source's texels, one block of a compressed side for one texel of an uncompressed one.
void copyImageImage(const Image& src, const Image& dst, const VkImageCopy2& r);

// Encodes a clear color for `format` into `texel` (texelSize bytes). Returns false for unknown formats.
bool encodeClearColor(const FormatInfo& format, const VkClearColorValue& color, uint8_t* texel);

// Fills the subresources of `range` (VK_REMAINING_* allowed) with the encoded texel (every sample).
void clearImage(const Image& image, const uint8_t* texel, const VkImageSubresourceRange& range);
// Fills `range`'s depth and/or stencil aspects (range.aspectMask) of a depth/stencil image with `value`, keeping
// the other aspect's bytes.
void clearDepthStencilImage(const Image& image, const VkClearDepthStencilValue& value,
                            const VkImageSubresourceRange& range);
// Encodes depth / stencil into one texel of `format` (only the aspect's bytes are written).
void encodeDepth(VkFormat format, float depth, uint8_t* texel);
void encodeStencil(VkFormat format, uint32_t stencil, uint8_t* texel);
// Resolves one region of a multisampled image into a single-sampled one of the same format: the average of the
// samples for float and normalized formats (sRGB averaged in linear space), sample 0 for integer formats.
void resolveImage(const Image& src, const Image& dst, const VkImageResolve2& r);
// One pixel: `src` holds `samples` consecutive texels of `f`; the result is written to `dst`
// (runtime/image_resolve.cpp).
void resolveColorPixel(const FormatInfo& f, const uint8_t* src, uint32_t samples, uint8_t* dst);
// One pixel of one aspect of a depth/stencil format with a resolve mode (SAMPLE_ZERO, AVERAGE for depth, MIN, MAX);
// only that aspect's bytes of `dst` are written.
void resolveDepthStencilPixel(VkFormat format, VkImageAspectFlags aspect, VkResolveModeFlagBits mode,
                              const uint8_t* src, uint32_t samples, uint8_t* dst);

// IEEE-style unsigned/signed small floats: 16-bit half (sign, 5-bit exponent, 10-bit mantissa) and the
// unsigned 11/10-bit floats of B10G11R11, rounded to nearest even.
uint16_t floatToHalf(float f);
uint32_t floatToUnsignedSmallFloat(float f, int mantissaBits);

}  // namespace vkrt
