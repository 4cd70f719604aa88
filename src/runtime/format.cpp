#include "runtime/format.hpp"

#include <algorithm>
#include <array>

#include "runtime/acceleration_structure_build.hpp"
#include "runtime/alloc.hpp"
#include "runtime/physical_device.hpp"
#include "runtime/supported_features.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {
namespace {

using N = NumericType;

constexpr FormatInfo kFormats[] = {
    {VK_FORMAT_R8_UNORM, 1, 1, {8}, N::UNorm, false, false},
    {VK_FORMAT_R8_SNORM, 1, 1, {8}, N::SNorm, false, false},
    {VK_FORMAT_R8_UINT, 1, 1, {8}, N::UInt, false, false},
    {VK_FORMAT_R8_SINT, 1, 1, {8}, N::SInt, false, false},
    {VK_FORMAT_R8G8_UNORM, 2, 2, {8, 8}, N::UNorm, false, false},
    {VK_FORMAT_R8G8_SNORM, 2, 2, {8, 8}, N::SNorm, false, false},
    {VK_FORMAT_R8G8_UINT, 2, 2, {8, 8}, N::UInt, false, false},
    {VK_FORMAT_R8G8_SINT, 2, 2, {8, 8}, N::SInt, false, false},
    // The packed 16-bit formats of "Mandatory Format Support: Sub-Byte Components" (fields from bit 0 up).
    {VK_FORMAT_B4G4R4A4_UNORM_PACK16, 2, 4, {4, 4, 4, 4}, N::UNorm, false, true, 0, true},
    {VK_FORMAT_R5G6B5_UNORM_PACK16, 2, 3, {5, 6, 5}, N::UNorm, true, true},
    {VK_FORMAT_A1R5G5B5_UNORM_PACK16, 2, 4, {5, 5, 5, 1}, N::UNorm, true, true},
    {VK_FORMAT_R8G8B8A8_UNORM, 4, 4, {8, 8, 8, 8}, N::UNorm, false, false},
    {VK_FORMAT_R8G8B8A8_SNORM, 4, 4, {8, 8, 8, 8}, N::SNorm, false, false},
    {VK_FORMAT_R8G8B8A8_UINT, 4, 4, {8, 8, 8, 8}, N::UInt, false, false},
    {VK_FORMAT_R8G8B8A8_SINT, 4, 4, {8, 8, 8, 8}, N::SInt, false, false},
    {VK_FORMAT_R8G8B8A8_SRGB, 4, 4, {8, 8, 8, 8}, N::SRGB, false, false},
    {VK_FORMAT_B8G8R8A8_UNORM, 4, 4, {8, 8, 8, 8}, N::UNorm, true, false},
    {VK_FORMAT_B8G8R8A8_SRGB, 4, 4, {8, 8, 8, 8}, N::SRGB, true, false},
    // A8B8G8R8_*_PACK32: R in bits 0..7 ... A in bits 24..31, on a little-endian host the bytes of R8G8B8A8.
    {VK_FORMAT_A8B8G8R8_UNORM_PACK32, 4, 4, {8, 8, 8, 8}, N::UNorm, false, false},
    {VK_FORMAT_A8B8G8R8_SNORM_PACK32, 4, 4, {8, 8, 8, 8}, N::SNorm, false, false},
    {VK_FORMAT_A8B8G8R8_UINT_PACK32, 4, 4, {8, 8, 8, 8}, N::UInt, false, false},
    {VK_FORMAT_A8B8G8R8_SINT_PACK32, 4, 4, {8, 8, 8, 8}, N::SInt, false, false},
    {VK_FORMAT_A8B8G8R8_SRGB_PACK32, 4, 4, {8, 8, 8, 8}, N::SRGB, false, false},
    {VK_FORMAT_A2B10G10R10_UNORM_PACK32, 4, 4, {10, 10, 10, 2}, N::UNorm, false, true},
    {VK_FORMAT_A2B10G10R10_UINT_PACK32, 4, 4, {10, 10, 10, 2}, N::UInt, false, true},
    {VK_FORMAT_B10G11R11_UFLOAT_PACK32, 4, 3, {11, 11, 10}, N::UFloat, false, true},
    // Three 9-bit mantissas (R from bit 0) and a 5-bit exponent they share (bits 27..31); decodeTexel knows it.
    {VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4, 3, {9, 9, 9}, N::UFloat, false, true},
    {VK_FORMAT_R16_UNORM, 2, 1, {16}, N::UNorm, false, false},
    {VK_FORMAT_R16_SNORM, 2, 1, {16}, N::SNorm, false, false},
    {VK_FORMAT_R16G16_UNORM, 4, 2, {16, 16}, N::UNorm, false, false},
    {VK_FORMAT_R16G16_SNORM, 4, 2, {16, 16}, N::SNorm, false, false},
    {VK_FORMAT_R16_UINT, 2, 1, {16}, N::UInt, false, false},
    {VK_FORMAT_R16_SINT, 2, 1, {16}, N::SInt, false, false},
    {VK_FORMAT_R16_SFLOAT, 2, 1, {16}, N::SFloat, false, false},
    {VK_FORMAT_R16G16_UINT, 4, 2, {16, 16}, N::UInt, false, false},
    {VK_FORMAT_R16G16_SINT, 4, 2, {16, 16}, N::SInt, false, false},
    {VK_FORMAT_R16G16_SFLOAT, 4, 2, {16, 16}, N::SFloat, false, false},
    {VK_FORMAT_R16G16B16A16_UNORM, 8, 4, {16, 16, 16, 16}, N::UNorm, false, false},
    {VK_FORMAT_R16G16B16A16_SNORM, 8, 4, {16, 16, 16, 16}, N::SNorm, false, false},
    {VK_FORMAT_R16G16B16A16_UINT, 8, 4, {16, 16, 16, 16}, N::UInt, false, false},
    {VK_FORMAT_R16G16B16A16_SINT, 8, 4, {16, 16, 16, 16}, N::SInt, false, false},
    {VK_FORMAT_R16G16B16A16_SFLOAT, 8, 4, {16, 16, 16, 16}, N::SFloat, false, false},
    {VK_FORMAT_R32_UINT, 4, 1, {32}, N::UInt, false, false},
    {VK_FORMAT_R32_SINT, 4, 1, {32}, N::SInt, false, false},
    {VK_FORMAT_R32_SFLOAT, 4, 1, {32}, N::SFloat, false, false},
    {VK_FORMAT_R32G32_UINT, 8, 2, {32, 32}, N::UInt, false, false},
    {VK_FORMAT_R32G32_SINT, 8, 2, {32, 32}, N::SInt, false, false},
    {VK_FORMAT_R32G32_SFLOAT, 8, 2, {32, 32}, N::SFloat, false, false},
    {VK_FORMAT_R32G32B32_UINT, 12, 3, {32, 32, 32}, N::UInt, false, false},
    {VK_FORMAT_R32G32B32_SINT, 12, 3, {32, 32, 32}, N::SInt, false, false},
    {VK_FORMAT_R32G32B32_SFLOAT, 12, 3, {32, 32, 32}, N::SFloat, false, false},
    {VK_FORMAT_R32G32B32A32_UINT, 16, 4, {32, 32, 32, 32}, N::UInt, false, false},
    {VK_FORMAT_R32G32B32A32_SINT, 16, 4, {32, 32, 32, 32}, N::SInt, false, false},
    {VK_FORMAT_R32G32B32A32_SFLOAT, 16, 4, {32, 32, 32, 32}, N::SFloat, false, false},
    // Depth/stencil: the FormatInfo decodes depth (as R) or, for S8_UINT, stencil.
    {VK_FORMAT_D16_UNORM, 2, 1, {16}, N::UNorm, false, false},
    {VK_FORMAT_X8_D24_UNORM_PACK32, 4, 1, {24}, N::UNorm, false, false},
    {VK_FORMAT_D32_SFLOAT, 4, 1, {32}, N::SFloat, false, false},
    {VK_FORMAT_S8_UINT, 1, 1, {8}, N::UInt, false, false},
    {VK_FORMAT_D24_UNORM_S8_UINT, 4, 1, {24}, N::UNorm, false, false},
    {VK_FORMAT_D32_SFLOAT_S8_UINT, 8, 1, {32}, N::SFloat, false, false},
    // The BC formats ("Compressed Image Formats", "Block-Compressed Image Formats"): 4x4 blocks of 8 or 16 bytes,
    // decoded to the components and type below (runtime/bc_texel.cpp); BC1_RGB has no alpha (read as 1).
    {VK_FORMAT_BC1_RGB_UNORM_BLOCK, 8, 3, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC1_RGB_SRGB_BLOCK, 8, 3, {}, N::SRGB, false, false, 0, false, 4},
    {VK_FORMAT_BC1_RGBA_UNORM_BLOCK, 8, 4, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC1_RGBA_SRGB_BLOCK, 8, 4, {}, N::SRGB, false, false, 0, false, 4},
    {VK_FORMAT_BC2_UNORM_BLOCK, 16, 4, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC2_SRGB_BLOCK, 16, 4, {}, N::SRGB, false, false, 0, false, 4},
    {VK_FORMAT_BC3_UNORM_BLOCK, 16, 4, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC3_SRGB_BLOCK, 16, 4, {}, N::SRGB, false, false, 0, false, 4},
    {VK_FORMAT_BC4_UNORM_BLOCK, 8, 1, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC4_SNORM_BLOCK, 8, 1, {}, N::SNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC5_UNORM_BLOCK, 16, 2, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC5_SNORM_BLOCK, 16, 2, {}, N::SNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC6H_UFLOAT_BLOCK, 16, 3, {}, N::UFloat, false, false, 0, false, 4},
    {VK_FORMAT_BC6H_SFLOAT_BLOCK, 16, 3, {}, N::SFloat, false, false, 0, false, 4},
    {VK_FORMAT_BC7_UNORM_BLOCK, 16, 4, {}, N::UNorm, false, false, 0, false, 4},
    {VK_FORMAT_BC7_SRGB_BLOCK, 16, 4, {}, N::SRGB, false, false, 0, false, 4},
};

// The compatibility class of a BC format ("Format Compatibility Classes": 64-bit BC1_RGB, 64-bit BC1_RGBA,
// 128-bit BC2, BC3, 64-bit BC4, 128-bit BC5, BC6H, BC7): the format that opens its pair.
VkFormat bcClass(VkFormat f) {
  switch (f) {
    case VK_FORMAT_BC1_RGB_SRGB_BLOCK: return VK_FORMAT_BC1_RGB_UNORM_BLOCK;
    case VK_FORMAT_BC1_RGBA_SRGB_BLOCK: return VK_FORMAT_BC1_RGBA_UNORM_BLOCK;
    case VK_FORMAT_BC2_SRGB_BLOCK: return VK_FORMAT_BC2_UNORM_BLOCK;
    case VK_FORMAT_BC3_SRGB_BLOCK: return VK_FORMAT_BC3_UNORM_BLOCK;
    case VK_FORMAT_BC4_SNORM_BLOCK: return VK_FORMAT_BC4_UNORM_BLOCK;
    case VK_FORMAT_BC5_SNORM_BLOCK: return VK_FORMAT_BC5_UNORM_BLOCK;
    case VK_FORMAT_BC6H_SFLOAT_BLOCK: return VK_FORMAT_BC6H_UFLOAT_BLOCK;
    case VK_FORMAT_BC7_SRGB_BLOCK: return VK_FORMAT_BC7_UNORM_BLOCK;
    default: return f;
  }
}

// The stencil aspects of the combined formats.
constexpr FormatInfo kD24S8Stencil{VK_FORMAT_D24_UNORM_S8_UINT, 4, 1, {8}, N::UInt, false, false, 3};
constexpr FormatInfo kD32S8Stencil{VK_FORMAT_D32_SFLOAT_S8_UINT, 8, 1, {8}, N::UInt, false, false, 4};

// The color formats the spec's "Required Format Support" tables mark COLOR_ATTACHMENT (vkrt renders to every
// color format it has but the three-component 32-bit ones, buffer-only, and the shared-exponent E5B9G9R9; B10G11R11,
// whose encode is rounding only, is included). Blending applies to all but the integer formats.
bool colorAttachment(const FormatInfo& f) {
  return f.texelSize != 12 && f.format != VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 && f.block == 1;
}

// formatInfo's index of kFormats by the format's value, for the core formats (values below kIndexed; -1: none): the
// image functions resolve a view's format on every call, and a search of the table took up to 78 comparisons.
constexpr uint32_t kIndexed = 256;
constexpr std::array<int16_t, kIndexed> kIndexByFormat = [] {
  std::array<int16_t, kIndexed> t{};
  for (int16_t& i : t) i = -1;
  for (size_t i = 0; i < std::size(kFormats); ++i)
    if (uint32_t(kFormats[i].format) < kIndexed) t[uint32_t(kFormats[i].format)] = int16_t(i);
  return t;
}();

}  // namespace

const FormatInfo* formatInfo(VkFormat format) {
  if (uint32_t(format) < kIndexed) {
    const int16_t i = kIndexByFormat[uint32_t(format)];
    return i >= 0 ? &kFormats[i] : nullptr;
  }
  for (const FormatInfo& f : kFormats)  // formats of extensions (values from 1000000000 on)
    if (f.format == format) return &f;
  return nullptr;
}

std::span<const FormatInfo> allFormats() { return kFormats; }

bool isCompressedFormat(VkFormat format) {
  const FormatInfo* f = formatInfo(format);
  return f && f->block > 1;
}

bool viewFormatCompatible(VkFormat image, VkFormat view, VkImageCreateFlags flags) {
  const FormatInfo* i = formatInfo(image);
  const FormatInfo* v = formatInfo(view);
  if (!i || !v) return false;
  if (image == view) return true;
  if (i->block > 1 && v->block > 1) return bcClass(image) == bcClass(view);
  // "Size-compatible": an uncompressed view of a compressed image whose texel is one block.
  if (i->block > 1) return (flags & VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT) && v->texelSize == i->texelSize;
  return v->block == 1 && v->texelSize == i->texelSize;
}

bool isDepthStencilFormat(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return true;
    default: return false;
  }
}

VkImageAspectFlags formatAspects(VkFormat format) {
  switch (format) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D32_SFLOAT: return VK_IMAGE_ASPECT_DEPTH_BIT;
    case VK_FORMAT_S8_UINT: return VK_IMAGE_ASPECT_STENCIL_BIT;
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    default: return formatInfo(format) ? VK_IMAGE_ASPECT_COLOR_BIT : 0;
  }
}

const FormatInfo* aspectFormatInfo(VkFormat format, VkImageAspectFlags aspect) {
  if (aspect == VK_IMAGE_ASPECT_STENCIL_BIT) {
    if (format == VK_FORMAT_D24_UNORM_S8_UINT) return &kD24S8Stencil;
    if (format == VK_FORMAT_D32_SFLOAT_S8_UINT) return &kD32S8Stencil;
  }
  return formatInfo(format);
}

uint32_t aspectBufferTexelSize(VkFormat format, VkImageAspectFlags aspect) {
  if (aspect == VK_IMAGE_ASPECT_STENCIL_BIT) return 1;
  if (aspect == VK_IMAGE_ASPECT_DEPTH_BIT) return format == VK_FORMAT_D16_UNORM ? 2 : 4;
  const FormatInfo* f = formatInfo(format);
  return f ? f->texelSize : 0;
}

uint32_t aspectImageBytes(VkFormat format, VkImageAspectFlags aspect) {
  if (aspect == VK_IMAGE_ASPECT_DEPTH_BIT &&
      (format == VK_FORMAT_D24_UNORM_S8_UINT || format == VK_FORMAT_X8_D24_UNORM_PACK32))
    return 3;
  return aspectBufferTexelSize(format, aspect);
}

bool isColorAttachmentFormat(VkFormat format) {
  const FormatInfo* f = formatInfo(format);
  return f && !isDepthStencilFormat(format) && colorAttachment(*f);
}

VkFormatFeatureFlags formatFeatures(VkFormat format) {
  const FormatInfo* f = formatInfo(format);
  if (!f || f->texelSize == 12) return 0;  // three-component 32-bit formats are buffer-only
  // The BC formats ("Mandatory format support: BC compressed formats": SAMPLED_IMAGE, BLIT_SRC,
  // SAMPLED_IMAGE_FILTER_LINEAR) and copies: the image functions decode the texel's block wherever a shader or a
  // blit reads one (runtime/bc_texel.cpp), copies move whole blocks (runtime/image_copy.cpp). Nothing writes texels
  // of a compressed format: no attachment, storage, blit destination or clear. None without textureCompressionBC in
  // the supported features (runtime/supported_features.cpp): the formats and the feature come together.
  if (f->block > 1)
    return !supportedFeatures()[size_t(Feature::textureCompressionBC)]
               ? 0
               : VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
                     VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT |
                     VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  if (isDepthStencilFormat(format)) {
    // Depth/stencil attachments (gfx/rendering.cpp clears, resolves and hands them to the rasterizer), copies per
    // aspect (runtime/image_copy.cpp), sampling (depth as R, stencil as an unsigned integer; linear filtering of
    // depth). Blits: BLIT_SRC as the spec's table requires it of D16_UNORM and D32_SFLOAT only; no format is a
    // depth BLIT_DST, so no depth blit is valid (they need equal formats).
    VkFormatFeatureFlags ds = VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT |
                              VK_FORMAT_FEATURE_TRANSFER_DST_BIT | VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
    if (formatAspects(format) & VK_IMAGE_ASPECT_DEPTH_BIT) ds |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
    if (format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_D32_SFLOAT) ds |= VK_FORMAT_FEATURE_BLIT_SRC_BIT;
    return ds;
  }
  // E5B9G9R9 ("Mandatory Format Support: 64-bit/uneven Components" asks sampled, filtered, blit source): copies and
  // blits both ways too (clears and blit destinations through encodeTexel's rounding to the shared exponent); no
  // attachment or storage (neither required; the rasterizer and the storage paths are not tested with it).
  if (format == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32)
    return VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
           VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT | VK_FORMAT_FEATURE_BLIT_DST_BIT |
           VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  // Every image format blits both ways: vkCmdBlitImage decodes, filters and encodes any of them
  // (runtime/image_blit.cpp), which covers the BLIT_SRC/BLIT_DST rows of the spec's "Required Format Support".
  VkFormatFeatureFlags flags = VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
                               VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_BLIT_SRC_BIT |
                               VK_FORMAT_FEATURE_BLIT_DST_BIT;
  // Linear filtering (sampling and VK_FILTER_LINEAR blits) for every format but the integer ones, which the spec
  // never filters.
  if (f->type != N::UInt && f->type != N::SInt) flags |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT;
  if (f->type != N::SRGB) flags |= VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
  // Color attachments (gfx/rendering.cpp, raster's back end through the texel codecs), blended unless integer.
  if (colorAttachment(*f)) {
    flags |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT;
    if (f->type != N::UInt && f->type != N::SInt) flags |= VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT;
  }
  if (format == VK_FORMAT_R32_UINT || format == VK_FORMAT_R32_SINT) flags |= VK_FORMAT_FEATURE_STORAGE_IMAGE_ATOMIC_BIT;
  return flags;
}

// Linear tiling: as optimal, but compressed images are optimal only (their tests are; nothing asks for more).
VkFormatFeatureFlags linearFormatFeatures(VkFormat format) {
  return isCompressedFormat(format) ? 0 : formatFeatures(format);
}

VkFormatFeatureFlags2 formatFeatures2(VkFormat format) {
  VkFormatFeatureFlags2 flags = formatFeatures(format);
  // Formats ("Formats Without Shader Storage Format"): with shaderStorageImage{Read,Write}WithoutFormat supported,
  // Vulkan 1.3 requires these bits for the listed formats that support storage images, and a storage format with
  // no SPIR-V Image Format (B8G8R8A8_UNORM) must have one of them. vkrt reports both for every storage format:
  // the image functions convert texels from and to the view's format whatever the shader declares.
  if (flags & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT)
    flags |= VK_FORMAT_FEATURE_2_STORAGE_READ_WITHOUT_FORMAT_BIT | VK_FORMAT_FEATURE_2_STORAGE_WRITE_WITHOUT_FORMAT_BIT;
  // Depth comparison (OpImage*Dref*, "Depth Compare Operation") on the depth aspect of every sampled depth format:
  // the image functions compare each texel's depth before filtering (runtime/image_functions.cpp).
  if ((flags & VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT) && (formatAspects(format) & VK_IMAGE_ASPECT_DEPTH_BIT))
    flags |= VK_FORMAT_FEATURE_2_SAMPLED_IMAGE_DEPTH_COMPARISON_BIT;
  return flags;
}

bool vertexBufferFormat(VkFormat f) {
  if (f < VK_FORMAT_R8_UNORM || f > VK_FORMAT_R32G32B32A32_SFLOAT) return false;
  return f != VK_FORMAT_R8_SRGB && f != VK_FORMAT_R8G8_SRGB && f != VK_FORMAT_R8G8B8_SRGB &&
         f != VK_FORMAT_B8G8R8_SRGB && f != VK_FORMAT_R8G8B8A8_SRGB && f != VK_FORMAT_B8G8R8A8_SRGB &&
         f != VK_FORMAT_A8B8G8R8_SRGB_PACK32;
}

VkFormatFeatureFlags bufferFormatFeatures(VkFormat format) {
  // Vertex formats of acceleration structure builds (the spec's mandatory ones and the 8/16-bit normalized ones), and
  // of vertex input (src/gfx/vertex_input.cpp).
  const VkFormatFeatureFlags vertex =
      (accelerationStructureVertexFormat(format) ? VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR : 0) |
      (vertexBufferFormat(format) ? VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT : 0);
  const FormatInfo* f = formatInfo(format);
  if (!f || f->type == N::SRGB || isDepthStencilFormat(format) || format == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32 ||
      f->block > 1)
    return vertex;
  VkFormatFeatureFlags flags =
      vertex | VK_FORMAT_FEATURE_UNIFORM_TEXEL_BUFFER_BIT | VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_BIT;
  if (format == VK_FORMAT_R32_UINT || format == VK_FORMAT_R32_SINT)
    flags |= VK_FORMAT_FEATURE_STORAGE_TEXEL_BUFFER_ATOMIC_BIT;
  return flags;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceFormatProperties(VkPhysicalDevice, VkFormat format,
                                                                  VkFormatProperties* pFormatProperties) {
  pFormatProperties->linearTilingFeatures = linearFormatFeatures(format);
  pFormatProperties->optimalTilingFeatures = formatFeatures(format);
  pFormatProperties->bufferFeatures = bufferFormatFeatures(format);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceFormatProperties2(VkPhysicalDevice physicalDevice, VkFormat format,
                                                                   VkFormatProperties2* pFormatProperties) {
  vkrt_GetPhysicalDeviceFormatProperties(physicalDevice, format, &pFormatProperties->formatProperties);
  for (auto* s = static_cast<VkBaseOutStructure*>(pFormatProperties->pNext); s; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3) {
      auto* p3 = reinterpret_cast<VkFormatProperties3*>(s);
      p3->linearTilingFeatures = isCompressedFormat(format) ? 0 : formatFeatures2(format);
      p3->optimalTilingFeatures = formatFeatures2(format);
      // Storage texel buffers are not compiled yet: no format-less access to them.
      p3->bufferFeatures = bufferFormatFeatures(format);
    }
  }
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceImageFormatProperties(
    VkPhysicalDevice physicalDevice, VkFormat format, VkImageType type, VkImageTiling tiling, VkImageUsageFlags usage,
    VkImageCreateFlags flags, VkImageFormatProperties* pProps) {
  *pProps = {};
  VkFormatFeatureFlags features =
      tiling == VK_IMAGE_TILING_LINEAR ? linearFormatFeatures(format) : formatFeatures(format);
  if (!features) return VK_ERROR_FORMAT_NOT_SUPPORTED;
  // VK_IMAGE_CREATE_EXTENDED_USAGE_BIT with MUTABLE_FORMAT: a usage may be one that only some format of the image's
  // views supports ("Image Creation Limits"); the views of a mutable color image may have any color format of its
  // texel size (vkrt's formats are uncompressed: one compatibility class per size, "Format Compatibility Classes").
  // The view's own format then has to support it (vkCreateImageView).
  // A compressed image's views are of its BC class or, with BLOCK_TEXEL_VIEW_COMPATIBLE, uncompressed formats of its
  // block size (viewFormatCompatible), which are sampled and storage views of its blocks but no attachments: the
  // render paths address attachments by the image's extent in texels, not in blocks.
  const VkImageCreateFlags extended = VK_IMAGE_CREATE_EXTENDED_USAGE_BIT | VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT;
  if ((flags & extended) == extended && !isDepthStencilFormat(format)) {
    const VkFormatFeatureFlags noAttachment = isCompressedFormat(format)
                                                  ? ~VkFormatFeatureFlags(VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT |
                                                                          VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT)
                                                  : ~VkFormatFeatureFlags(0);
    for (const FormatInfo& f : kFormats)
      if (viewFormatCompatible(format, f.format, flags)) features |= formatFeatures(f.format) & noAttachment;
  }
  // Each usage needs its format feature ("Image Creation Limits").
  const struct {
    VkImageUsageFlags usage;
    VkFormatFeatureFlags feature;
  } kNeeds[] = {
      {VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_FORMAT_FEATURE_TRANSFER_SRC_BIT},
      {VK_IMAGE_USAGE_TRANSFER_DST_BIT, VK_FORMAT_FEATURE_TRANSFER_DST_BIT},
      {VK_IMAGE_USAGE_SAMPLED_BIT, VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT},
      {VK_IMAGE_USAGE_STORAGE_BIT, VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT},
      {VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT},
      {VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT},
      // Transient attachments are ordinary memory; input attachments are read by shaders through the texel codecs
      // every attachment format has (runtime/image_functions.cpp vkrt_image_read_subpass), so either attachment
      // feature admits them.
      {VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
       VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT},
      {VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT,
       VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT},
  };
  VkImageUsageFlags known = 0;
  for (const auto& n : kNeeds) {
    known |= n.usage;
    if ((usage & n.usage) && !(features & n.feature)) return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  if (usage & ~known) return VK_ERROR_FORMAT_NOT_SUPPORTED;
  // Depth/stencil images are 2D ("Depth/Stencil Formats": vkrt keeps them to the required image type).
  if (isDepthStencilFormat(format) && type != VK_IMAGE_TYPE_2D) return VK_ERROR_FORMAT_NOT_SUPPORTED;
  // Compressed images are 2D (arrays and cube-compatible ones too) and 3D, as "Mandatory format support: BC
  // compressed formats" lists them; not 1D.
  if (isCompressedFormat(format) && type == VK_IMAGE_TYPE_1D) return VK_ERROR_FORMAT_NOT_SUPPORTED;
  if (flags &
      (VK_IMAGE_CREATE_SPARSE_BINDING_BIT | VK_IMAGE_CREATE_SPARSE_RESIDENCY_BIT | VK_IMAGE_CREATE_SPARSE_ALIASED_BIT))
    return VK_ERROR_FORMAT_NOT_SUPPORTED;
  const VkPhysicalDeviceLimits& l = fromHandleUnchecked<PhysicalDevice>(physicalDevice)->properties10.limits;
  switch (type) {
    case VK_IMAGE_TYPE_1D:
      pProps->maxExtent = {l.maxImageDimension1D, 1, 1};
      pProps->maxMipLevels = 15;
      break;
    case VK_IMAGE_TYPE_2D:
      pProps->maxExtent = {l.maxImageDimension2D, l.maxImageDimension2D, 1};
      pProps->maxMipLevels = 15;
      break;
    case VK_IMAGE_TYPE_3D:
      pProps->maxExtent = {l.maxImageDimension3D, l.maxImageDimension3D, l.maxImageDimension3D};
      pProps->maxMipLevels = 12;
      break;
    default: return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  pProps->maxArrayLayers = type == VK_IMAGE_TYPE_3D ? 1 : l.maxImageArrayLayers;
  // 4 samples for 2D optimal images that can be attachments ("Supported Sample Counts": the framebuffer and
  // sampled-image sample counts are 1 | 4); storage images stay single-sampled (storageImageSampleCounts).
  pProps->sampleCounts = VK_SAMPLE_COUNT_1_BIT;
  if (type == VK_IMAGE_TYPE_2D && tiling == VK_IMAGE_TILING_OPTIMAL && !(flags & VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT) &&
      !(usage & VK_IMAGE_USAGE_STORAGE_BIT) &&
      (features & (VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT | VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT)))
    pProps->sampleCounts |= VK_SAMPLE_COUNT_4_BIT;
  pProps->maxResourceSize = 1ull << 32;
  return VK_SUCCESS;
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_GetPhysicalDeviceImageFormatProperties2(
    VkPhysicalDevice physicalDevice, const VkPhysicalDeviceImageFormatInfo2* pInfo, VkImageFormatProperties2* pProps) {
  // External memory (core in Vulkan 1.1, VK_KHR_external_memory): vkrt exports and imports no handle type, so an
  // image with one is not supported; handle type 0 is as if the structure were absent.
  auto* external = findInChain<VkPhysicalDeviceExternalImageFormatInfo>(
      pInfo->pNext, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_IMAGE_FORMAT_INFO);
  if (external && external->handleType) {
    pProps->imageFormatProperties = {};
    return VK_ERROR_FORMAT_NOT_SUPPORTED;
  }
  // VkImageStencilUsageCreateInfo: the stencil aspect's usage, which must be supported as well; both aspects share
  // the format's features, so the pair is supported when their union is. Formats without stencil ignore it.
  VkImageUsageFlags usage = pInfo->usage;
  if (formatAspects(pInfo->format) & VK_IMAGE_ASPECT_STENCIL_BIT)
    if (auto* su =
            findInChain<VkImageStencilUsageCreateInfo>(pInfo->pNext, VK_STRUCTURE_TYPE_IMAGE_STENCIL_USAGE_CREATE_INFO))
      usage |= su->stencilUsage;
  return vkrt_GetPhysicalDeviceImageFormatProperties(physicalDevice, pInfo->format, pInfo->type, pInfo->tiling, usage,
                                                     pInfo->flags, &pProps->imageFormatProperties);
}

VKAPI_ATTR void VKAPI_CALL vkrt_GetPhysicalDeviceSparseImageFormatProperties(VkPhysicalDevice, VkFormat, VkImageType,
                                                                             VkSampleCountFlagBits, VkImageUsageFlags,
                                                                             VkImageTiling, uint32_t* pPropertyCount,
                                                                             VkSparseImageFormatProperties*) {
  *pPropertyCount = 0;  // no sparse support
}

VKAPI_ATTR void VKAPI_CALL
vkrt_GetPhysicalDeviceSparseImageFormatProperties2(VkPhysicalDevice, const VkPhysicalDeviceSparseImageFormatInfo2*,
                                                   uint32_t* pPropertyCount, VkSparseImageFormatProperties2*) {
  *pPropertyCount = 0;
}

}  // extern "C"
