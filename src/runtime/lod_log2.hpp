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
// FMA form where the CPU has one): x = 2^e m with m in [sqrt(1/2), sqrt(2)), log2(m) = t q(t) with t = m - 1 and q a
// polynomial of degree 7 (least squares on Chebyshev nodes of that interval), evaluated in Estrin's form: within
// 1.3e-7 of log2 (checked in float at 200,001 points of the interval), far finer than the 2^-mipmapPrecisionBits
// (2^-8) the level's weight needs, and exact at powers of two (t = 0: the result is e). No division and a short
// dependent chain: the level of detail is on the critical path of every implicit-LOD sample (a series in
// (m - 1) / (m + 1) evaluated by Horner's rule, before, cost the quad sampler's callers 4-7% of a raster frame). 0:
// -inf; infinity and NaN as themselves (negative values do not occur: sums of squares).
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
  const Float4 t = m - 1.0f, t2 = t * t, t4 = t2 * t2;
  const Float4 q01 = 1.44269478f + -0.721357584f * t, q23 = 0.480932325f + -0.360064656f * t;
  const Float4 q45 = 0.286885113f + -0.250497341f * t, q67 = 0.235715508f + -0.143023819f * t;
  const Float4 q = (q01 + t2 * q23) + t4 * (q45 + t2 * q67);
  const Float4 r = __builtin_convertvector(e, Float4) + t * q;
  const Float4 inf = {INFINITY, INFINITY, INFINITY, INFINITY};
  return x == 0.0f ? -inf : x < inf ? r : x;
}

}  // namespace vkrt
