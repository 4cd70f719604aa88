// The runtime's side of the image functions compiled shaders call (declared in src/abi/image_functions.hpp):
// they read the ImageView and Sampler objects a descriptor record points at. Texel encoding and decoding and
// filtering are here too, shared with vkCmdBlitImage (runtime/image_blit.cpp), which samples its source as a
// shader samples an image view ("Image Copies With Scaling").
#pragma once

#include <cstdint>

#include "abi/image_functions.hpp"
#include "runtime/format.hpp"

namespace vkrt {

class Image;

// Decodes / encodes one texel of `format` (format.hpp) to / from four 32-bit words.
void decodeTexel(const FormatInfo& format, const uint8_t* texel, uint32_t out[4]);
void encodeTexel(const FormatInfo& format, const uint32_t in[4], uint8_t* texel);

// What the sampling code addresses: mip levels [baseMip, +levelCount) and layers [baseLayer, +layerCount) of an
// image, as an image view sees them, or as vkCmdBlitImage sees one layer of its source subresource.
struct TexelView {
  const Image* image = nullptr;
  const FormatInfo* format = nullptr;
  uint32_t baseMip = 0, levelCount = 1, baseLayer = 0, layerCount = 1;
  int dims = 2;  // coordinate components before the layer: 1 (1D), 2 (2D, cube), 3 (3D)
  bool arrayed = false;
  bool slicesAsLayers = false;  // a 2D (array) view of a 3D image: layers are depth slices
};

// Texel filtering within level `level` of `v` ("Texel Filtering"): `coord` holds v.dims coordinates, normalized
// unless s.unnormalizedCoordinates; `layer` is the layer index relative to v.baseLayer; the sampler's address
// modes and border colour apply. Writes four words as decodeTexel does: float bits for float and normalized
// formats (NEAREST: one texel; LINEAR: the weighted average of 2, 4 or 8), the nearest texel's integers for
// integer formats (never filtered).
void filterTexels(const TexelView& v, const VkSamplerCreateInfo& s, VkFilter filter, uint32_t level, const float* coord,
                  int64_t layer, uint32_t out[4]);

// The image functions by symbol name (null-terminated), for the compiler's HostSymbol lists.
const abi::HostSymbol* imageFunctionSymbols();

}  // namespace vkrt
