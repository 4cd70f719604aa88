// The sRGB transfer functions ("sRGB EOTF" and its inverse, the Khronos Data Format Specification's), as the image
// functions decode and encode sRGB components (runtime/image_functions.cpp) and BC texels are decoded
// (runtime/bc_texel.cpp). linearToSrgb clamps to [0, 1] first (a NaN stays NaN).
#pragma once

#include <algorithm>
#include <cmath>

namespace vkrt {

inline float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

inline float linearToSrgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

}  // namespace vkrt
