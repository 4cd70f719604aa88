// The formats vkrt supports, with their texel layout and format features. One table, used by the format
// queries, image creation and the copy/clear/shader image code.
#pragma once

#include <cstdint>

#include "runtime/vk.hpp"

namespace vkrt {

enum class NumericType : uint8_t { UNorm, SNorm, UInt, SInt, SFloat, SRGB, UFloat };

struct FormatInfo {
  VkFormat format;
  uint8_t texelSize;   // bytes per texel
  uint8_t components;  // 1..4
  uint8_t bits[4];     // bits per component, in memory order R,G,B,A (B,G,R,A for the BGRA formats)
  NumericType type;
  bool bgr;     // components stored as B,G,R(,A)
  bool packed;  // a packed format (A2B10G10R10, B10G11R11...)
};

// nullptr when vkrt does not support the format.
const FormatInfo* formatInfo(VkFormat format);

// Format features vkrt supports for optimal/linear tiling and buffers (identical for both tilings).
VkFormatFeatureFlags formatFeatures(VkFormat format);
VkFormatFeatureFlags bufferFormatFeatures(VkFormat format);
// Whether `format` is a vertex buffer format (VK_FORMAT_FEATURE_VERTEX_BUFFER_BIT): the formats src/gfx/vertex_input.cpp
// converts, every 8/16/32-bit UNORM, SNORM, USCALED, SSCALED, UINT, SINT and SFLOAT format from R8_UNORM to
// R32G32B32A32_SFLOAT (the packed 8- and 10-bit ones included), sRGB excepted.
bool vertexBufferFormat(VkFormat format);
// The image features as VkFormatProperties3 reports them: formatFeatures() and the bits only VkFormatFeatureFlags2
// has (STORAGE_READ/WRITE_WITHOUT_FORMAT on every storage format).
VkFormatFeatureFlags2 formatFeatures2(VkFormat format);

}  // namespace vkrt
