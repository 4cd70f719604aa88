// The runtime's texel codecs (decodeTexel/encodeTexel, what the graphics layer passes as ColorFormat::decode/encode)
// in the rasterizer's callback shape, for tests that compare the back end's paths with them.
#pragma once

#include "runtime/format.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt::raster::test {

inline void decodeRuntime(const void* f, const uint8_t* t, uint32_t out[4]) {
  decodeTexel(*static_cast<const FormatInfo*>(f), t, out);
}
inline void encodeRuntime(const void* f, const uint32_t in[4], uint8_t* t) {
  encodeTexel(*static_cast<const FormatInfo*>(f), in, t);
}

}  // namespace vkrt::raster::test
