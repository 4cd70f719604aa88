// The quad sampler's vector fast path (quad_sampling.hpp): the four lanes of vkrt_image_sample_grad_quad in the four
// elements of each vector, for the level of detail, the coordinates, the level selection, the texel addressing and
// the filter. Each step repeats the per-lane fast path's (image_functions.cpp: lodOfDerivatives, biasedLod,
// fastAtLod, fastSample, fastCoord, fixedCoord, fastFilterLevel) operation for operation, so every lane's result is
// the same bits as that lane's vkrt_image_sample_grad; where the per-lane path takes two shapes, the vector path
// takes the one that gives the other's result exactly:
//   - NEAREST is LINEAR with both texels of each axis the nearest one and weights 0: t + 0 (t - t) is t.
//   - one level (mipmap NEAREST, or a whole level of detail) is two levels, the same twice, at weight 0: a (1 - 0) +
//     b 0 is a, for the texels' values are never negative (no -0 either).
// Lanes may select different levels and filters; only the texel loads are per lane (SSE2 has no gather). The sRGB
// decoding, the address modes and the filters (both NEAREST, both LINEAR, or by lane) are template parameters,
// chosen once per call (sampleQuadFast).
#include "runtime/quad_sampling.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "runtime/lod_log2.hpp"

namespace vkrt {

namespace {

using Float4 = LodFloat4;
using Int4 = LodInt4;
using Double4 = double __attribute__((vector_size(32)));  // two SSE2 registers on the baseline target
using Long4 = int64_t __attribute__((vector_size(32)));

// The lanes of a mask (elements 0 or -1) as bits.
inline uint32_t maskBits(Int4 m) { return uint32_t((m[0] & 1) | (m[1] & 2) | (m[2] & 4) | (m[3] & 8)); }

inline Float4 load4(const float* p) {
  Float4 v;
  std::memcpy(&v, p, 16);
  return v;
}

inline uint32_t load32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// std::clamp(v, lo, hi) per element, as libstdc++ computes it: std::min(std::max(v, lo), hi) (a NaN stays NaN).
inline Float4 clamp4(Float4 v, Float4 lo, Float4 hi) {
  const Float4 t = v < lo ? lo : v;
  return hi < t ? hi : t;
}

// fastCoord: REPEAT's fraction, c - floor(c) in double (the coordinates are below 2^24 in magnitude: a 32-bit
// truncation is floorInt's 64-bit one).
// (Results through a pointer: a 32-byte vector returned by value is an ABI the baseline target lacks.)
template <bool repeat>
__attribute__((always_inline)) inline void quadCoord(Float4 c, Double4* out) {
  const Double4 d = __builtin_convertvector(c, Double4);
  if constexpr (!repeat) {
    *out = d;
    return;
  }
  const Double4 t = __builtin_convertvector(__builtin_convertvector(d, Int4), Double4);
  const Double4 one = {1.0, 1.0, 1.0, 1.0};
  *out = d - (t > d ? t - one : t);
}

// One axis of fastFilterLevel for the four lanes at their levels' sizes `size`: the first and second texel indices
// after the address mode and the LINEAR weight, or the NEAREST texel twice and weight 0 (`linear` false).
struct Axis {
  Int4 i0, i1;
  Float4 weight;
};
// `filter`: kLinear or kNearest for every lane, kMixed where `linear` says.
enum FilterCase { kNearest, kLinear, kMixed };
template <bool repeat, FilterCase filter>
__attribute__((always_inline)) inline Axis quadAxis(const Double4& c, Int4 size, const Long4& linear64, Int4 linear) {
  const Double4 sized = __builtin_convertvector(size, Double4);
  Double4 u = c * sized;  // fixedCoord
  if constexpr (!repeat) {
    const Double4 lo = {-1.0, -1.0, -1.0, -1.0}, one = {1.0, 1.0, 1.0, 1.0};
    const Double4 hi = sized + one;
    u = u < lo ? lo : u > hi ? hi : u;
  }
  const Double4 linearOffset = {1.5, 1.5, 1.5, 1.5}, nearestOffset = {2.0, 2.0, 2.0, 2.0};  // 2 - half
  constexpr double kScale = double(1 << kSubTexelBits);
  const Double4 scale = {kScale, kScale, kScale, kScale};
  Double4 offset;
  if constexpr (filter == kLinear)
    offset = linearOffset;
  else if constexpr (filter == kNearest)
    offset = nearestOffset;
  else
    offset = linear64 ? linearOffset : nearestOffset;
  const Int4 x = __builtin_convertvector((u + offset) * scale, Int4);
  const Int4 f = (x >> kSubTexelBits) - 2, last = size - 1, zero = {0, 0, 0, 0};
  Axis a;
  // LINEAR: REPEAT's first index is in [-1, size - 1], so only it wraps below and the second above.
  Int4 l0 = zero, l1 = zero, nw = zero;
  if constexpr (filter != kNearest) {
    const Int4 next = f + 1;
    l0 = repeat ? f + (size & (f < zero)) : (f < zero ? zero : f >= size ? last : f);
    l1 = repeat ? next & ~(next >= size) : (next < zero ? zero : next >= size ? last : next);
  }
  if constexpr (filter != kLinear) {
    // NEAREST: std::min(f, size - 1), then wrapFast.
    const Int4 n = last < f ? last : f;
    nw = repeat ? (n < zero ? last : n >= size ? zero : n) : (n < zero ? zero : n >= size ? last : n);
  }
  constexpr float kInv = float(1.0 / double(1 << kSubTexelBits));
  if constexpr (filter == kLinear) {
    a.i0 = l0;
    a.i1 = l1;
    a.weight = __builtin_convertvector(x & ((1 << kSubTexelBits) - 1), Float4) * kInv;
  } else if constexpr (filter == kNearest) {
    a.i0 = a.i1 = nw;
    a.weight = Float4{0, 0, 0, 0};
  } else {
    a.i0 = linear ? l0 : nw;
    a.i1 = linear ? l1 : nw;
    const Float4 w = __builtin_convertvector(x & ((1 << kSubTexelBits) - 1), Float4) * kInv;
    a.weight = (Float4)((Int4)w & linear);
  }
  return a;
}

// The four texels' components (component k of lane l at [k][l]) of the texels at `offset` (bytes from each lane's
// base): UNorm in byte units, sRGB decoded by decodeTexel's tables.
template <bool srgb>
__attribute__((always_inline)) inline void quadTexels(const QuadView& v, const uint8_t* const base[4],
                                                      const uint64_t offset[4], Float4 out[4]) {
  const unsigned r = v.bgr ? 2 : 0;
  if constexpr (srgb) {
    for (unsigned l = 0; l < 4; ++l) {
      const uint8_t* p = base[l] + offset[l];
      out[0][l] = v.srgbTable[p[r]];
      out[1][l] = v.srgbTable[p[1]];
      out[2][l] = v.srgbTable[p[2 - r]];
      out[3][l] = v.unormTable[p[3]];
    }
    return;
  }
  const Int4 t = {int32_t(load32(base[0] + offset[0])), int32_t(load32(base[1] + offset[1])),
                  int32_t(load32(base[2] + offset[2])), int32_t(load32(base[3] + offset[3]))};
  const Int4 byte = {0xff, 0xff, 0xff, 0xff};
  out[0] = __builtin_convertvector((t >> (8 * r)) & byte, Float4);
  out[1] = __builtin_convertvector((t >> 8) & byte, Float4);
  out[2] = __builtin_convertvector((t >> (16 - 8 * r)) & byte, Float4);
  out[3] = __builtin_convertvector((t >> 24) & byte, Float4);  // arithmetic shift: the mask keeps the byte
}

// fastFilterLevel for the four lanes, each at its level `level` and layer, LINEAR where `linear`.
template <bool srgb, bool repeatU, bool repeatV, FilterCase filter>
__attribute__((always_inline)) inline void quadFilterLevel(const QuadView& v, Int4 level, Int4 linear,
                                                           const Double4& cu, const Double4& cv, const int64_t layer[4],
                                                           Float4 out[4]) {
  Int4 w, h;
  const uint8_t* base[4];
  uint64_t pitch[4];
  for (unsigned l = 0; l < 4; ++l) {
    const QuadLevel& m = v.levels[level[l]];
    w[l] = m.width;
    h[l] = m.height;
    base[l] = m.layer0 + uint64_t(layer[l]) * m.arrayPitch;
    pitch[l] = m.rowPitch;
  }
  const Long4 linear64 = __builtin_convertvector(linear, Long4);
  const Axis x = quadAxis<repeatU, filter>(cu, w, linear64, linear);
  const Axis y = quadAxis<repeatV, filter>(cv, h, linear64, linear);
  uint64_t o00[4], o10[4], o01[4], o11[4];
  for (unsigned l = 0; l < 4; ++l) {
    const uint64_t row0 = uint64_t(y.i0[l]) * pitch[l], row1 = uint64_t(y.i1[l]) * pitch[l];
    const uint64_t c0 = uint64_t(x.i0[l]) * 4, c1 = uint64_t(x.i1[l]) * 4;  // fastSampling's pixelSize
    o00[l] = row0 + c0;
    o10[l] = row0 + c1;
    o01[l] = row1 + c0;
    o11[l] = row1 + c1;
  }
  Float4 t00[4], t10[4], t01[4], t11[4];
  quadTexels<srgb>(v, base, o00, t00);
  quadTexels<srgb>(v, base, o10, t10);
  quadTexels<srgb>(v, base, o01, t01);
  quadTexels<srgb>(v, base, o11, t11);
  for (unsigned k = 0; k < 4; ++k) {
    const Float4 top = t00[k] + x.weight * (t10[k] - t00[k]), bottom = t01[k] + x.weight * (t11[k] - t01[k]);
    out[k] = top + y.weight * (bottom - top);
  }
}

template <bool srgb, bool repeatU, bool repeatV, FilterCase filter>
uint32_t sampleQuad(const QuadView& v, const QuadSampler& s, const float coord[16], const float ddx[16],
                    const float ddy[16], const float bias[4], uint32_t lanes, uint32_t out[16], float lod[4]) {
  // lodOfDerivatives (a 2D view: two components, scaled by the base level's size), then biasedLod.
  const Float4 zero = {0, 0, 0, 0};
  Float4 rx = zero, ry = zero;
  for (unsigned i = 0; i < 2; ++i) {
    const float scale = v.size[i];
    const Float4 dx = load4(ddx + 4 * i), dy = load4(ddy + 4 * i);
    rx += (dx * scale) * (dx * scale);
    ry += (dy * scale) * (dy * scale);
  }
  Float4 lambda = 0.5f * lodLog2(rx < ry ? ry : rx);
  lambda = lambda == lambda ? lambda : zero;
  const Float4 b = load4(bias);
  lambda = b == b ? lambda + b : lambda;
  lambda = lambda + s.mipLodBias;
  std::memcpy(lod, &lambda, 16);

  // fastAtLod: the sampler's clamp, the filter, the level of detail within the view's levels.
  lambda = clamp4(lambda, zero + s.minLod, zero + s.maxLod);
  const Int4 magLinear = Int4{} - int32_t(s.magLinear), minLinear = Int4{} - int32_t(s.minLinear);
  const Int4 linear = lambda <= 0.0f ? magLinear : minLinear;
  const float maxLevel = float(v.levelCount - 1);
  Float4 d = clamp4(lambda, zero, zero + maxLevel);
  // fastSample's refusals: NaN, and coordinates of magnitude 2^24 or more (or NaN); the generic path takes them.
  Float4 cu = load4(coord), cv = load4(coord + 4);
  const Int4 magnitude = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};
  const Int4 ok = d == d && (Float4)((Int4)cu & magnitude) < 0x1p24f && (Float4)((Int4)cv & magnitude) < 0x1p24f;
  const uint32_t done = maskBits(ok) & lanes;
  const uint32_t rest = lanes & ~done;
  // The other lanes sample (0, 0) at level 0: any valid operands, for their results are discarded.
  Int4 doneMask;
  for (unsigned l = 0; l < 4; ++l) doneMask[l] = done >> l & 1 ? -1 : 0;
  cu = (Float4)((Int4)cu & doneMask);
  cv = (Float4)((Int4)cv & doneMask);
  d = (Float4)((Int4)d & doneMask);
  int64_t layer[4] = {0, 0, 0, 0};
  if (v.arrayed) {
    // arrayLayer: the array coordinate rounded, then clamped to the view's layers.
    for (unsigned l = 0; l < 4; ++l) {
      const float c = std::nearbyint(coord[8 + l]);
      if (done >> l & 1) layer[l] = int64_t(std::clamp(c, 0.0f, float(v.layerCount - 1)));
    }
  }
  Double4 u, w;
  quadCoord<repeatU>(cu, &u);
  quadCoord<repeatV>(cv, &w);

  // The level selection (d is in [0, maxLevel]: floor and ceil by truncation): mipmap NEAREST or a whole d, level
  // ceil(d + 0.5) - 1; else levels floor(d) and the next, weighed by d's fraction.
  const Int4 levelMax = Int4{} + int32_t(v.levelCount - 1);
  const Int4 lo = __builtin_convertvector(d, Int4);
  const Float4 lof = __builtin_convertvector(lo, Float4);
  const Int4 single = s.mipLinear ? d == lof : Int4{} - 1;
  const Float4 half = d + 0.5f;
  const Int4 xi = __builtin_convertvector(half, Int4);
  const Int4 up = xi + (__builtin_convertvector(xi, Float4) < half ? Int4{} + 1 : Int4{});
  const Int4 nearestLevel = levelMax < up - 1 ? levelMax : up - 1;
  const Int4 hi = levelMax < lo + 1 ? levelMax : lo + 1;
  Float4 r[4];
  quadFilterLevel<srgb, repeatU, repeatV, filter>(v, single ? nearestLevel : lo, linear, u, w, layer, r);
  if ((maskBits(single) & done) != done) {
    // Two levels where any lane blends (the single-level lanes read their level again, at weight 0).
    Float4 second[4];
    const Float4 t = (Float4)((Int4)(d - lof) & ~single);
    quadFilterLevel<srgb, repeatU, repeatV, filter>(v, single ? nearestLevel : hi, linear, u, w, layer, second);
    for (unsigned k = 0; k < 4; ++k) r[k] = r[k] * (1.0f - t) + second[k] * t;
  }
  for (unsigned k = 0; k < 4; ++k) {
    if constexpr (!srgb) r[k] *= 1.0f / 255.0f;  // sRGB texels came from the tables, already in 0..1
    const Int4 bits = (Int4)r[k] & doneMask;
    std::memcpy(out + 4 * k, &bits, 16);
  }
  return rest;
}

}  // namespace

// The variant of the view's decoding, the sampler's address modes and filters.
uint32_t sampleQuadFast(const QuadView& v, const QuadSampler& s, const float coord[16], const float ddx[16],
                        const float ddy[16], const float bias[4], uint32_t lanes, uint32_t out[16], float lod[4]) {
  using Fn = uint32_t (*)(const QuadView&, const QuadSampler&, const float*, const float*, const float*, const float*,
                          uint32_t, uint32_t*, float*);
#define VKRT_QUAD_FILTERS(srgb, u, v) \
  sampleQuad<srgb, u, v, kNearest>, sampleQuad<srgb, u, v, kLinear>, sampleQuad<srgb, u, v, kMixed>
#define VKRT_QUAD_MODES(srgb)                                                                                        \
  VKRT_QUAD_FILTERS(srgb, false, false), VKRT_QUAD_FILTERS(srgb, false, true), VKRT_QUAD_FILTERS(srgb, true, false), \
      VKRT_QUAD_FILTERS(srgb, true, true)
  static constexpr Fn kVariants[] = {VKRT_QUAD_MODES(false), VKRT_QUAD_MODES(true)};
#undef VKRT_QUAD_MODES
#undef VKRT_QUAD_FILTERS
  const FilterCase filter = s.magLinear != s.minLinear ? kMixed : s.magLinear ? kLinear : kNearest;
  const unsigned index = unsigned(v.srgb) * 12 + unsigned(s.repeatU) * 6 + unsigned(s.repeatV) * 3 + unsigned(filter);
  return kVariants[index](v, s, coord, ddx, ddy, bias, lanes, out, lod);
}

}  // namespace vkrt
