// Decoders for the block-compressed formats of textureCompressionBC: S3TC (BC1-3), RGTC (BC4-5) and BPTC
// (BC6H, BC7), one 4x4 block at a time, as the Khronos Data Format Specification 1.3 defines them (sections
// "S3TC Compressed Texture Image Formats", "RGTC Compressed Texture Image Formats" and "BPTC Compressed Texture
// Image Formats"). Knows no Vulkan type: the format table maps VkFormats to a Kind, copies move whole blocks, and
// texel fetches decode the block that holds the texel.
//
// Thread safety: decodeBlock is a pure function of its input (no state, no heap allocation), callable from any
// number of threads at once.
#pragma once

#include <cstdint>

namespace vkrt::bc {

enum class Kind {
  BC1_RGB,
  BC1_RGBA,
  BC2,
  BC3,
  BC4_UNORM,
  BC4_SNORM,
  BC5_UNORM,
  BC5_SNORM,
  BC6H_UFLOAT,
  BC6H_SFLOAT,
  BC7
};

// Bytes of one 4x4 block: 8 for BC1 and BC4, 16 for the others.
constexpr uint32_t blockBytes(Kind k) {
  return k == Kind::BC1_RGB || k == Kind::BC1_RGBA || k == Kind::BC4_UNORM || k == Kind::BC4_SNORM ? 8 : 16;
}

// Decodes one 4x4 block into its 16 texels, row-major (texel (x, y) at index y * 4 + x), RGBA float each:
// UNORM values in [0, 1] and SNORM in [-1, 1] as the Khronos Data Format Specification's decoding defines them,
// BC6H the half-float values it defines (as float), components the format lacks as (0, 0, 0, 1) per Vulkan's rules
// (BC1_RGB and BC4/BC5/BC6H alpha 1; BC4: (r, 0, 0, 1); BC5: (r, g, 0, 1)). No sRGB decoding (the caller converts
// RGB of the _SRGB formats). Never reads more than blockBytes(kind) bytes; every bit pattern is valid input
// (reserved BC6H modes decode to (0, 0, 0, 1), the BC7 byte 0 without a mode bit to (0, 0, 0, 0)).
void decodeBlock(Kind kind, const uint8_t* block, float out[16][4]);

}  // namespace vkrt::bc
