// The runtime's side of the image functions compiled shaders call (declared in src/abi/image_functions.hpp):
// they read the ImageView and Sampler objects a descriptor record points at. Texel encoding and decoding is
// here too, shared with the image transfer commands' tests.
#pragma once

#include <cstdint>

#include "abi/image_functions.hpp"
#include "runtime/format.hpp"

namespace vkrt {

// Decodes / encodes one texel of `format` (format.hpp) to / from four 32-bit words.
void decodeTexel(const FormatInfo& format, const uint8_t* texel, uint32_t out[4]);
void encodeTexel(const FormatInfo& format, const uint32_t in[4], uint8_t* texel);

// The image functions by symbol name (null-terminated), for the compiler's HostSymbol lists.
const abi::HostSymbol* imageFunctionSymbols();

}  // namespace vkrt
