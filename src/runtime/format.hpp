// The formats vkrt supports, with their texel layout and format features. One table, used by the format
// queries, image creation and the copy/clear/shader image code.
#pragma once

#include <cstdint>
#include <span>

#include "runtime/vk.hpp"

namespace vkrt {

enum class NumericType : uint8_t { UNorm, SNorm, UInt, SInt, SFloat, SRGB, UFloat };

struct FormatInfo {
  VkFormat format;
  uint8_t texelSize;   // bytes per texel
  uint8_t components;  // 1..4
  // Bits per component in memory order: R,G,B,A (B,G,R,A for the BGRA formats); for packed formats from the least
  // significant bit up (A2B10G10R10: R,G,B,A; R5G6B5: B,G,R; B4G4R4A4: A,R,G,B).
  uint8_t bits[4];
  NumericType type;
  bool bgr;     // components stored as B,G,R(,A)
  bool packed;  // a packed format (A2B10G10R10, B10G11R11, R5G6B5...): one texelSize-byte word, fields from bit 0 up
  // The byte of the texel where the decoded components start: 0, except for the stencil aspect of a combined
  // depth/stencil format (aspectFormatInfo), which reads one byte inside the combined texel.
  uint8_t offset = 0;
  // A packed format whose lowest field is A, followed by R, G, B (B4G4R4A4_UNORM_PACK16).
  bool alphaLow = false;
  // The texel block's width and height ("Compressed Image Formats"): 1 for uncompressed formats, 4 for the BC
  // formats, whose texelSize is the bytes of one 4x4 block (8 for BC1 and BC4, 16 for the others) and whose
  // components and type are those the block decodes to (runtime/bc_texel.hpp); `bits` is unused for them.
  uint8_t block = 1;
};

// Depth/stencil formats (the spec's "Depth/Stencil Formats"), stored as their texels: D16_UNORM 2 bytes,
// X8_D24_UNORM_PACK32 4 bytes (depth in bits 0..23), D32_SFLOAT 4 bytes, S8_UINT 1 byte, D24_UNORM_S8_UINT 4 bytes
// (depth in bits 0..23, stencil in byte 3), D32_SFLOAT_S8_UINT 8 bytes (depth in bytes 0..3, stencil in byte 4,
// bytes 5..7 unused). Their FormatInfo decodes the depth (as R); the stencil aspect has its own (aspectFormatInfo).
VkImageAspectFlags formatAspects(VkFormat format);  // COLOR, or DEPTH and/or STENCIL; 0 for unknown formats
bool isDepthStencilFormat(VkFormat format);
// The texels of one aspect of `format` as decodeTexel/encodeTexel see them (texelSize stays the whole texel's):
// the format's own FormatInfo for color and depth, an S8 reader at byte 3 / 4 for the stencil of combined formats.
const FormatInfo* aspectFormatInfo(VkFormat format, VkImageAspectFlags aspect);
// Bytes a texel of one aspect takes in a buffer (vkCmdCopyBufferToImage, "Depth/Stencil Formats" packing): depth
// of D16 2, of the D24 formats 4 (the top byte undefined on reads), of the D32 formats 4; stencil 1.
uint32_t aspectBufferTexelSize(VkFormat format, VkImageAspectFlags aspect);
// Bytes of the image texel one aspect's copy writes (D24 depth: 3, so the stencil byte is kept).
uint32_t aspectImageBytes(VkFormat format, VkImageAspectFlags aspect);
// Whether the format can be a color attachment / has blending (COLOR_ATTACHMENT(_BLEND) in formatFeatures).
bool isColorAttachmentFormat(VkFormat format);

// nullptr when vkrt does not support the format.
const FormatInfo* formatInfo(VkFormat format);
// Every format formatInfo knows, each once (the tests).
std::span<const FormatInfo> allFormats();

// A block-compressed format vkrt knows (the sixteen BC formats).
bool isCompressedFormat(VkFormat format);
// Whether `view` may be the format of a view of an image of `image` format created with `flags` ("Format
// Compatibility Classes"): the same class (an uncompressed format: the same texel size; a BC format: the same BC
// family, e.g. BC1_RGB_UNORM and BC1_RGB_SRGB), or, with VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT on a
// compressed image, an uncompressed format whose texel size is the block size (size-compatible). False where either
// format is unknown.
bool viewFormatCompatible(VkFormat image, VkFormat view, VkImageCreateFlags flags);

// Format features vkrt supports for optimal tiling and buffers; linear tiling has the same but for the compressed
// formats, which have none (linearFormatFeatures).
VkFormatFeatureFlags formatFeatures(VkFormat format);
VkFormatFeatureFlags linearFormatFeatures(VkFormat format);
VkFormatFeatureFlags bufferFormatFeatures(VkFormat format);
// Whether `format` is a vertex buffer format (VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT): the formats
// src/gfx/vertex_input.cpp converts, every 8/16/32-bit UNORM, SNORM, USCALED, SSCALED, UINT, SINT and SFLOAT format
// from R8_UNORM to R32G32B32A32_SFLOAT (the packed 8- and 10-bit ones included), sRGB excepted.
bool vertexBufferFormat(VkFormat format);
// The image features as VkFormatProperties3 reports them: formatFeatures() and the bits only VkFormatFeatureFlags2
// has (STORAGE_READ/WRITE_WITHOUT_FORMAT on every storage format).
VkFormatFeatureFlags2 formatFeatures2(VkFormat format);

}  // namespace vkrt
