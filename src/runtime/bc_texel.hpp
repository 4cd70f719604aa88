// Texels of the BC formats as the image functions read them: one texel of a 4x4 block through the block decoders
// of runtime/bc_decode.hpp, in the four words decodeTexel gives for other formats.
#pragma once

#include <cstdint>

#include "runtime/format.hpp"

namespace vkrt {

// Decodes texel (x, y) (each 0..3) of the block at `block` of BC format `f` (f.block == 4) into four float words:
// sRGB formats' R, G, B converted to linear ("sRGB EOTF"), the components the format lacks substituted ("Component
// Substitution": G and B 0, A 1; BC1_RGB's alpha 1), BC4 and BC5 SNORM in [-1, 1], BC6H as the half floats it holds.
// No allocation and no lock: the decoded block lives on the stack.
void decodeBcTexel(const FormatInfo& f, const uint8_t* block, uint32_t x, uint32_t y, uint32_t out[4]);

}  // namespace vkrt
