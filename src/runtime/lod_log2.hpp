// log2 of four values for the level of detail, shared by the image functions' gradient forms
// (runtime/image_functions.cpp) and the quad sampler's vector path (runtime/quad_sampling.cpp), which must agree
// bit for bit.
#pragma once

#include <cmath>
#include <cstdint>

namespace vkrt {

using LodFloat4 = float __attribute__((vector_size(16)));
using LodInt4 = int32_t __attribute__((vector_size(16)));

// In plain float vector arithmetic (the same result on every x86-64 CPU, unlike the C library's log2f, which picks an
// FMA form where the CPU has one): x = 2^e m with m in [sqrt(1/2), sqrt(2)), ln(m) = 2 atanh(s), s = (m - 1) / (m +
// 1), |s| < 0.172, by its odd series to s^9 (the rest is below 1e-9 in log2): within a few ulp of log2, far finer
// than the 2^-mipmapPrecisionBits (2^-8) the level's weight needs. 0: -inf; infinity and NaN as themselves
// (negative values do not occur: sums of squares).
inline LodFloat4 lodLog2(LodFloat4 x) {
  using Float4 = LodFloat4;
  using Int4 = LodInt4;
  const Int4 subnormal = (Int4)x < 0x00800000;  // scaled into the normal range first
  const Float4 xs = subnormal ? x * 0x1p32f : x;
  const Int4 bits = (Int4)xs;
  Int4 e = ((bits >> 23) & 0xff) - 127 + (subnormal & -32);
  Float4 m = (Float4)((bits & 0x007fffff) | 0x3f800000);  // [1, 2)
  const Int4 big = m > 1.41421356f;
  m = big ? m * 0.5f : m;
  e -= big;  // true is -1
  const Float4 t = (m - 1.0f) / (m + 1.0f), t2 = t * t;
  const Float4 ln = 2.0f * t * (1.0f + t2 * (1.0f / 3 + t2 * (1.0f / 5 + t2 * (1.0f / 7 + t2 * (1.0f / 9)))));
  const Float4 r = __builtin_convertvector(e, Float4) + ln * 1.44269504f;  // 1 / ln 2
  const Float4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
  return x == 0.0f ? -inf : x < inf ? r : x;
}

}  // namespace vkrt
