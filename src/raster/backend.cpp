// The per-fragment operations after coverage ("Fragment Operations": Depth Bounds Test, Stencil Test, Depth Test,
// Sample Counting is not here; "The Framebuffer": Blending, Logical Operations, Color Write Mask), per sample.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <iterator>
#if defined(__SSE2__)
#include <immintrin.h>  // SSE2's min/max and conversions; AVX2's in the AVX2 copy of the quad writes
#endif

#include "abi/srgb8.hpp"
#include "exec/quad_isa.hpp"
#include "raster/internal.hpp"

namespace vkrt::raster::detail {
namespace {

inline uint8_t* texel(const Surface& s, uint32_t texelBytes, uint32_t layer, int32_t x, int32_t y, uint32_t sample) {
  return s.base + size_t(layer) * s.layerPitch + size_t(y) * s.rowPitch + (size_t(x) * s.samples + sample) * texelBytes;
}

// "a op b": the new value against the stored one; on vectors (the quad paths) a mask per lane.
template <typename T>
inline auto compare(CompareOp op, T a, T b) -> decltype(a < b) {
  using R = decltype(a < b);
  switch (op) {
    case CompareOp::Never: return R{};
    case CompareOp::Less: return a < b;
    case CompareOp::Equal: return a == b;
    case CompareOp::LessOrEqual: return a <= b;
    case CompareOp::Greater: return a > b;
    case CompareOp::NotEqual: return a != b;
    case CompareOp::GreaterOrEqual: return a >= b;
    case CompareOp::Always: return R{} == R{};  // true, or all ones
  }
  return R{};
}

uint32_t stencilValue(StencilOp op, uint32_t s, uint32_t ref) {
  switch (op) {
    case StencilOp::Keep: return s;
    case StencilOp::Zero: return 0;
    case StencilOp::Replace: return ref & 0xFF;
    case StencilOp::IncrementAndClamp: return s < 255 ? s + 1 : 255;
    case StencilOp::DecrementAndClamp: return s > 0 ? s - 1 : 0;
    case StencilOp::Invert: return ~s & 0xFF;
    case StencilOp::IncrementAndWrap: return (s + 1) & 0xFF;
    case StencilOp::DecrementAndWrap: return (s - 1) & 0xFF;
  }
  return s;
}

inline void applyStencil(uint8_t* p, const StencilFace& f, StencilOp op) {
  const uint32_t old = *p;
  const uint32_t v = stencilValue(op, old, f.reference);
  *p = uint8_t((old & ~f.writeMask) | (v & f.writeMask));
}

// Depth as the attachment stores it: unsigned normalized formats round to nearest ("Fixed-Point Data
// Conversions"); the stored bits (unorm) or the float's value are what the test compares.
struct DepthValue {
  uint32_t u;
  float f;
};

inline DepthValue toStored(DepthFormat fmt, float z) {
  DepthValue v{0, z};
  if (fmt == DepthFormat::D16UNorm) {
    v.u = uint32_t(std::lrint(double(std::clamp(z, 0.0f, 1.0f)) * 65535.0));
  } else if (fmt == DepthFormat::X8D24UNorm) {
    v.u = uint32_t(std::lrint(double(std::clamp(z, 0.0f, 1.0f)) * 16777215.0));
  }
  return v;
}

inline DepthValue readDepth(DepthFormat fmt, const uint8_t* p) {
  DepthValue v{0, 0};
  if (fmt == DepthFormat::D16UNorm) {
    uint16_t d;
    std::memcpy(&d, p, 2);
    v.u = d, v.f = float(d / 65535.0);
  } else if (fmt == DepthFormat::X8D24UNorm) {
    uint32_t d;
    std::memcpy(&d, p, 4);
    v.u = d & 0xFFFFFFu, v.f = float(v.u / 16777215.0);
  } else {
    std::memcpy(&v.f, p, 4);
  }
  return v;
}

inline void writeDepth(DepthFormat fmt, uint8_t* p, DepthValue v) {
  if (fmt == DepthFormat::D16UNorm) {
    const uint16_t d = uint16_t(v.u);
    std::memcpy(p, &d, 2);
  } else if (fmt == DepthFormat::X8D24UNorm) {
    uint32_t d;
    std::memcpy(&d, p, 4);
    d = (d & 0xFF000000u) | v.u;  // the top 8 bits are kept (stencil, or X8 padding)
    std::memcpy(p, &d, 4);
  } else {
    std::memcpy(p, &v.f, 4);
  }
}

float blendFactor(BlendFactor f, uint32_t c, const float* s, const float* s1, const float* d, const float* k) {
  switch (f) {
    case BlendFactor::Zero: return 0;
    case BlendFactor::One: return 1;
    case BlendFactor::SrcColor: return s[c];
    case BlendFactor::OneMinusSrcColor: return 1 - s[c];
    case BlendFactor::DstColor: return d[c];
    case BlendFactor::OneMinusDstColor: return 1 - d[c];
    case BlendFactor::SrcAlpha: return s[3];
    case BlendFactor::OneMinusSrcAlpha: return 1 - s[3];
    case BlendFactor::DstAlpha: return d[3];
    case BlendFactor::OneMinusDstAlpha: return 1 - d[3];
    case BlendFactor::ConstantColor: return k[c];
    case BlendFactor::OneMinusConstantColor: return 1 - k[c];
    case BlendFactor::ConstantAlpha: return k[3];
    case BlendFactor::OneMinusConstantAlpha: return 1 - k[3];
    case BlendFactor::SrcAlphaSaturate: return c < 3 ? std::min(s[3], 1 - d[3]) : 1;
    case BlendFactor::Src1Color: return s1[c];
    case BlendFactor::OneMinusSrc1Color: return 1 - s1[c];
    case BlendFactor::Src1Alpha: return s1[3];
    case BlendFactor::OneMinusSrc1Alpha: return 1 - s1[3];
  }
  return 0;
}

// Whether a blend factor reads the destination (else it is the same for every sample of a fragment).
inline bool readsDestination(BlendFactor f) {
  return f == BlendFactor::DstColor || f == BlendFactor::OneMinusDstColor || f == BlendFactor::DstAlpha ||
         f == BlendFactor::OneMinusDstAlpha || f == BlendFactor::SrcAlphaSaturate;
}

inline float blendOp(BlendOp op, float s, float sf, float d, float df) {
  switch (op) {
    case BlendOp::Add: return s * sf + d * df;
    case BlendOp::Subtract: return s * sf - d * df;
    case BlendOp::ReverseSubtract: return d * df - s * sf;
    case BlendOp::Min: return std::min(s, d);
    case BlendOp::Max: return std::max(s, d);
  }
  return s;
}

inline uint8_t logicOp(LogicOp op, uint8_t s, uint8_t d) {
  switch (op) {
    case LogicOp::Clear: return 0;
    case LogicOp::And: return s & d;
    case LogicOp::AndReverse: return s & ~d;
    case LogicOp::Copy: return s;
    case LogicOp::AndInverted: return ~s & d;
    case LogicOp::NoOp: return d;
    case LogicOp::Xor: return s ^ d;
    case LogicOp::Or: return s | d;
    case LogicOp::Nor: return ~(s | d);
    case LogicOp::Equivalent: return ~(s ^ d);
    case LogicOp::Invert: return ~d;
    case LogicOp::OrReverse: return s | ~d;
    case LogicOp::CopyInverted: return ~s;
    case LogicOp::OrInverted: return ~s | d;
    case LogicOp::Nand: return ~(s & d);
    case LogicOp::Set: return 0xFF;
  }
  return s;
}

// Clamps the shader's value (or a blend result) to the range of a normalized format.
inline void clampToFormat(ColorFormat::Kind kind, float* v) {
  if (kind == ColorFormat::Kind::UNorm) {
    for (int c = 0; c < 4; ++c) v[c] = std::clamp(v[c], 0.0f, 1.0f);
  } else if (kind == ColorFormat::Kind::SNorm) {
    for (int c = 0; c < 4; ++c) v[c] = std::clamp(v[c], -1.0f, 1.0f);
  }
}

inline void loadFloats(const uint32_t* w, float* f) {
  for (int c = 0; c < 4; ++c) f[c] = asFloat(w[c]);
}

// Keeps the components outside `mask` from `dst` (words of the decoded texel).
inline void mergeMask(uint32_t* v, const uint32_t* dst, uint32_t mask) {
  for (int c = 0; c < 4; ++c)
    if (!(mask >> c & 1)) v[c] = dst[c];
}

// The inline codecs of ColorFormat::Layout's 8-bit UNorm layouts (the runtime's decode/encode, bit for bit).
struct Unorm8Table {
  float v[256];
  Unorm8Table() {
    for (uint32_t i = 0; i < 256; ++i) v[i] = float(double(i) / 255.0);
  }
};
const Unorm8Table kUnorm8;

inline uint32_t encodeUnorm8(uint32_t word) {
  float f = asFloat(word);
  f = std::isnan(f) ? 0.0f : std::clamp(f, 0.0f, 1.0f);
  // Times 255 in float, rounded to nearest even (the default rounding mode): adding and subtracting 2^23 leaves no
  // fraction bits for values in [0, 255].
  return uint32_t((f * 255.0f + 0x1p23f) - 0x1p23f);
}

using Words4 = float __attribute__((vector_size(16)));

// An 8-bit layout's texel (ColorFormat::Layout) to four floats: the colour components by `rgb` (kUnorm8's table, or
// abi/srgb8.hpp's for an sRGB layout), alpha by kUnorm8's.
inline Words4 decodeRgba8(const uint8_t* p, bool bgra, const float* rgb) {
  return Words4{rgb[p[bgra ? 2 : 0]], rgb[p[1]], rgb[p[bgra ? 0 : 2]], kUnorm8.v[p[3]]};
}

// Four floats (as words) to an 8-bit layout's texel: the colour components by encodeUnorm8, or by abi/srgb8.hpp's
// encode (NaN 0, clamped) for an sRGB layout; alpha by encodeUnorm8.
inline uint32_t encodeRgba8(const uint32_t in[4], bool bgra, bool srgb) {
  uint32_t r, g, b;
  if (srgb) {
    const abi::Srgb8Tables& t = abi::srgb8Tables();
    r = t.encode(asFloat(in[0])), g = t.encode(asFloat(in[1])), b = t.encode(asFloat(in[2]));
  } else {
    r = encodeUnorm8(in[0]), g = encodeUnorm8(in[1]), b = encodeUnorm8(in[2]);
  }
  return (bgra ? b | r << 16 : r | b << 16) | g << 8 | encodeUnorm8(in[3]) << 24;
}

// A texel's four components to words (floats), through the format's decode unless its layout is a fast one.
inline void decodeColor(const ColorFormat& fmt, const uint8_t* p, uint32_t out[4]) {
  if (fmt.layout == ColorFormat::Layout::Generic) return fmt.decode(fmt.format, p, out);
  // One 16-byte store: the words are read back as one vector, which four small stores would stall.
  const Words4 v = decodeRgba8(p, fmt.bgra(), fmt.srgb() ? abi::srgb8Tables().decode : kUnorm8.v);
  std::memcpy(out, &v, 16);
}

inline void encodeColor(const ColorFormat& fmt, const uint32_t in[4], uint8_t* p) {
  if (fmt.layout == ColorFormat::Layout::Generic) return fmt.encode(fmt.format, in, p);
  const uint32_t w = encodeRgba8(in, fmt.bgra(), fmt.srgb());
  std::memcpy(p, &w, 4);
}

// The 8-bit UNorm layouts (ColorFormat::Layout) without a logic op, four components at once: the
// same float operations, in the same order, per component as the generic path below (blendFactor, blendOp,
// clampToFormat, mergeMask), and the same codecs (decode by table, encode through double with rounding to nearest
// even), so the texels written are the same bit for bit.
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int32_t __attribute__((vector_size(16)));

inline Float4 splat(float v) { return Float4{v, v, v, v}; }
inline Float4 clamp01(Float4 v) {  // std::clamp(v, 0, 1) per component (NaN stays NaN)
#if defined(__SSE2__)
  // maxps/minps return their second operand when unordered: max(0, v) is "v < 0 ? 0 : v" and min(1, x) is
  // "1 < x ? 1 : x", std::clamp's two steps exactly (NaN and -0 kept), in two instructions.
  return Float4(_mm_min_ps(_mm_set1_ps(1.0f), _mm_max_ps(_mm_setzero_ps(), __m128(v))));
#else
  v = v < 0.0f ? splat(0.0f) : v;
  return 1.0f < v ? splat(1.0f) : v;
#endif
}

// NaN to 0, then [0, 1] (the encoders' clamp).
inline Float4 saturate(Float4 v) {
#if defined(__SSE2__)
  // max(v, 0) is "0 < v ? v : 0": NaN (unordered) and -0 give +0, which encode alike.
  return Float4(_mm_min_ps(_mm_max_ps(__m128(v), _mm_setzero_ps()), _mm_set1_ps(1.0f)));
#else
  return v == v ? clamp01(v) : splat(0);
#endif
}

// The blend factor `f` for all four components (component c of blendFactor(f, c, ...)).
inline Float4 blendFactor4(BlendFactor f, Float4 s, Float4 s1, Float4 d, Float4 k) {
  switch (f) {
    case BlendFactor::Zero: return splat(0);
    case BlendFactor::One: return splat(1);
    case BlendFactor::SrcColor: return s;
    case BlendFactor::OneMinusSrcColor: return 1.0f - s;
    case BlendFactor::DstColor: return d;
    case BlendFactor::OneMinusDstColor: return 1.0f - d;
    case BlendFactor::SrcAlpha: return splat(s[3]);
    case BlendFactor::OneMinusSrcAlpha: return splat(1.0f - s[3]);
    case BlendFactor::DstAlpha: return splat(d[3]);
    case BlendFactor::OneMinusDstAlpha: return splat(1.0f - d[3]);
    case BlendFactor::ConstantColor: return k;
    case BlendFactor::OneMinusConstantColor: return 1.0f - k;
    case BlendFactor::ConstantAlpha: return splat(k[3]);
    case BlendFactor::OneMinusConstantAlpha: return splat(1.0f - k[3]);
    case BlendFactor::SrcAlphaSaturate: {
      const float m = std::min(s[3], 1.0f - d[3]);
      return Float4{m, m, m, 1};
    }
    case BlendFactor::Src1Color: return s1;
    case BlendFactor::OneMinusSrc1Color: return 1.0f - s1;
    case BlendFactor::Src1Alpha: return splat(s1[3]);
    case BlendFactor::OneMinusSrc1Alpha: return splat(1.0f - s1[3]);
  }
  return splat(0);
}

inline Float4 blendOp4(BlendOp op, Float4 s, Float4 sf, Float4 d, Float4 df) {
  switch (op) {
    case BlendOp::Add: return s * sf + d * df;
    case BlendOp::Subtract: return s * sf - d * df;
    case BlendOp::ReverseSubtract: return d * df - s * sf;
    case BlendOp::Min: return d < s ? d : s;  // std::min(s, d)
    case BlendOp::Max: return s < d ? d : s;  // std::max(s, d)
  }
  return s;
}

// Color factors for R, G, B and the alpha factor for A.
inline Float4 colorAlpha(Float4 color, Float4 alpha) { return __builtin_shufflevector(color, alpha, 0, 1, 2, 7); }

// The four bytes widened at once and divided by 255: a correctly rounded division of exact operands, the same float
// as the table's double(i) / 255 rounded (i / 255 is never a tie between two floats).
inline Float4 loadUnorm8(const uint8_t* p, bool bgra) {
  using Bytes4 = uint8_t __attribute__((vector_size(4)));
  Bytes4 b;
  std::memcpy(&b, p, 4);
  const Float4 f = __builtin_convertvector(b, Float4) / 255.0f;
  return bgra ? __builtin_shufflevector(f, f, 2, 1, 0, 3) : f;
}

// The same for an sRGB layout (decodeColor's): the colour components by the decode table, alpha as UNorm.
inline Float4 loadSrgb8(const uint8_t* p, bool bgra) { return decodeRgba8(p, bgra, abi::srgb8Tables().decode); }

// Four values in [0, 1] times 255 in float, rounded to integers as encodeUnorm8 rounds them (its adding and
// subtracting of 2^23 rounds in the current rounding mode, as cvtps2dq does: the same integers in every mode).
inline Int4 unorm8Bytes(Float4 v) {
#if defined(__SSE2__)
  return Int4(_mm_cvtps_epi32(_mm_mul_ps(__m128(v), _mm_set1_ps(255.0f))));
#else
  return __builtin_convertvector((v * 255.0f + 0x1p23f) - 0x1p23f, Int4);
#endif
}

inline void storeUnorm8(Float4 v, uint8_t* p, bool bgra) {
  using Bytes4 = uint8_t __attribute__((vector_size(4)));
  Bytes4 b = __builtin_convertvector(unorm8Bytes(saturate(v)), Bytes4);  // 0..255
  if (bgra) b = __builtin_shufflevector(b, b, 2, 1, 0, 3);
  std::memcpy(p, &b, 4);
}

// The same for an sRGB layout (encodeColor's): the colour components by abi/srgb8.hpp's encode, alpha as UNorm.
inline void storeSrgb8(Float4 v, uint8_t* p, bool bgra) {
  uint32_t in[4];
  std::memcpy(in, &v, 16);
  const uint32_t w = encodeRgba8(in, bgra, true);
  std::memcpy(p, &w, 4);
}

// What writeUnorm8 needs of attachment i, once per quad.
struct Unorm8Target {
  const Surface* surf;
  const BlendAttachment* ba;
  bool bgra, srgb, blend, readsDst;
  Float4 k;
  Int4 keep;  // all ones where the write mask leaves the component
  Unorm8Target(const DrawContext& ctx, uint32_t i, uint32_t mask) {
    const State& st = *ctx.state;
    surf = &ctx.target->color[i];
    ba = &st.blend[i];
    bgra = ctx.target->colorFormat[i].bgra();
    srgb = ctx.target->colorFormat[i].srgb();
    blend = ba->enable;
    readsDst = blend || mask != 0xF;  // else the texel is replaced whole
    std::memcpy(&k, st.blendConstants, 16);
    k = clamp01(k);
    keep =
        Int4{int32_t(mask & 1) - 1, int32_t(mask >> 1 & 1) - 1, int32_t(mask >> 2 & 1) - 1, int32_t(mask >> 3 & 1) - 1};
  }
};

void writeUnorm8(const DrawContext& ctx, const Unorm8Target& t, const FragmentQuad& q, uint32_t lane, uint32_t i,
                 int32_t x, int32_t y, uint32_t coverage) {
  const BlendAttachment& ba = *t.ba;
  const Float4 k = t.k;
  Float4 s, s1;
  uint32_t words[4], words1[4];
  laneWords(q.color[i], lane, words);
  laneWords(q.color1, lane, words1);
  std::memcpy(&s, words, 16);
  std::memcpy(&s1, words1, 16);
  s = clamp01(s), s1 = clamp01(s1);
  for (uint32_t sm = coverage; sm; sm &= sm - 1) {
    uint8_t* p = texel(*t.surf, 4, ctx.layer, x, y, uint32_t(std::countr_zero(sm)));
    const Float4 d = !t.readsDst ? splat(0) : t.srgb ? loadSrgb8(p, t.bgra) : loadUnorm8(p, t.bgra);
    Float4 r = s;
    if (t.blend) {
      const Float4 sf = colorAlpha(blendFactor4(ba.srcColor, s, s1, d, k), blendFactor4(ba.srcAlpha, s, s1, d, k));
      const Float4 df = colorAlpha(blendFactor4(ba.dstColor, s, s1, d, k), blendFactor4(ba.dstAlpha, s, s1, d, k));
      r = clamp01(colorAlpha(blendOp4(ba.colorOp, s, sf, d, df), blendOp4(ba.alphaOp, s, sf, d, df)));
    }
    r = t.keep ? d : r;
    if (t.srgb)
      storeSrgb8(r, p, t.bgra);
    else
      storeUnorm8(r, p, t.bgra);
  }
}

// Whether attachment i takes writeUnorm8 (an 8-bit UNorm layout, no logic op) and its effective write mask.
inline bool unorm8Path(const DrawContext& ctx, uint32_t i, uint32_t* mask) {
  const ColorFormat& fmt = ctx.target->colorFormat[i];
  *mask = ctx.state->blend[i].writeMask & fmt.componentMask;
  return fmt.layout != ColorFormat::Layout::Generic && !ctx.state->logicOpEnable && fmt.encode;
}

void writeAttachment(const DrawContext& ctx, const FragmentQuad& q, uint32_t lane, uint32_t i, int32_t x, int32_t y,
                     uint32_t coverage) {
  const Target& tg = *ctx.target;
  const State& st = *ctx.state;
  const Surface& surf = tg.color[i];
  const ColorFormat& fmt = tg.colorFormat[i];
  const BlendAttachment& ba = st.blend[i];
  const uint32_t mask = ba.writeMask & fmt.componentMask;
  if (!mask || !fmt.encode) return;
  const bool integer = fmt.kind == ColorFormat::Kind::UInt || fmt.kind == ColorFormat::Kind::SInt;
  const bool normalized = fmt.kind == ColorFormat::Kind::UNorm || fmt.kind == ColorFormat::Kind::SNorm;
  const bool logic = st.logicOpEnable && fmt.kind != ColorFormat::Kind::Float;
  const bool blend = ba.enable && !integer && !st.logicOpEnable;
  const bool fullMask = mask == (fmt.componentMask & 0xF);
  uint32_t src[4];
  laneWords(q.color[i], lane, src);
  if (!integer) {
    float f[4];
    loadFloats(src, f);
    clampToFormat(fmt.kind, f);
    for (int c = 0; c < 4; ++c) src[c] = asWord(f[c]);
  }
  const uint32_t bytes = fmt.texelBytes;
  uint8_t encoded[16];
  if (!blend && !logic && fullMask) {
    encodeColor(fmt, src, encoded);
    for (uint32_t s = coverage; s; s &= s - 1)
      std::memcpy(texel(surf, bytes, ctx.layer, x, y, uint32_t(std::countr_zero(s))), encoded, bytes);
    return;
  }
  if (logic) encodeColor(fmt, src, encoded);
  float s0[4], s1[4], k[4];
  // The blend factors that do not read the destination, once for the lane's samples (the same values as per sample).
  float sfConst[4] = {}, dfConst[4] = {};
  bool sfPerSample = false, dfPerSample = false;
  if (blend) {
    loadFloats(src, s0);
    uint32_t words1[4];
    laneWords(q.color1, lane, words1);
    loadFloats(words1, s1);
    for (int c = 0; c < 4; ++c) k[c] = st.blendConstants[c];
    if (normalized) clampToFormat(fmt.kind, s1), clampToFormat(fmt.kind, k);
    sfPerSample = readsDestination(ba.srcColor) || readsDestination(ba.srcAlpha);
    dfPerSample = readsDestination(ba.dstColor) || readsDestination(ba.dstAlpha);
    const float none[4] = {0, 0, 0, 0};
    for (uint32_t c = 0; c < 4; ++c) {
      sfConst[c] = blendFactor(c == 3 ? ba.srcAlpha : ba.srcColor, c, s0, s1, none, k);
      dfConst[c] = blendFactor(c == 3 ? ba.dstAlpha : ba.dstColor, c, s0, s1, none, k);
    }
  }
  for (uint32_t sm = coverage; sm; sm &= sm - 1) {
    uint8_t* p = texel(surf, bytes, ctx.layer, x, y, uint32_t(std::countr_zero(sm)));
    uint32_t dst[4], out[4];
    decodeColor(fmt, p, dst);
    if (logic) {
      // Logical operations work on the texel's bits ("Logical Operations").
      uint8_t r[16];
      for (uint32_t b = 0; b < bytes; ++b) r[b] = logicOp(st.logicOp, encoded[b], p[b]);
      if (fullMask) {
        std::memcpy(p, r, bytes);
        continue;
      }
      decodeColor(fmt, r, out);
    } else if (blend) {
      float d[4], r[4];
      loadFloats(dst, d);
      for (uint32_t c = 0; c < 4; ++c) {
        const bool alpha = c == 3;
        const BlendFactor sf = alpha ? ba.srcAlpha : ba.srcColor, df = alpha ? ba.dstAlpha : ba.dstColor;
        const BlendOp op = alpha ? ba.alphaOp : ba.colorOp;
        const float sfv = sfPerSample ? blendFactor(sf, c, s0, s1, d, k) : sfConst[c];
        const float dfv = dfPerSample ? blendFactor(df, c, s0, s1, d, k) : dfConst[c];
        r[c] = blendOp(op, s0[c], sfv, d[c], dfv);
      }
      clampToFormat(fmt.kind, r);
      for (int c = 0; c < 4; ++c) out[c] = asWord(r[c]);
    } else {
      std::memcpy(out, src, 16);
    }
    mergeMask(out, dst, mask);
    encodeColor(fmt, out, p);
  }
}

}  // namespace

uint32_t alphaCoverage(float alpha, uint32_t samples) {
  // Alpha to coverage ("Multisample Coverage"): the first round(alpha * samples) samples.
  if (!(alpha > 0)) return 0;
  const uint32_t n = uint32_t(std::min<double>(std::floor(double(alpha) * samples + 0.5), samples));
  return (1u << n) - 1;
}

uint32_t depthStencilTests(const DrawContext& ctx, bool front, int32_t x, int32_t y, uint32_t coverage,
                           const float* z) {
  const State& st = *ctx.state;
  const DepthStencilTarget& ds = ctx.target->depthStencil;
  const bool hasDepth = ds.depthFormat != DepthFormat::None && ds.depth.base;
  const bool hasStencil = ds.stencilFormat != StencilFormat::None && ds.stencil.base;
  const bool bounds = st.depthBoundsTest && hasDepth;
  const bool stencil = st.stencilTest && hasStencil;
  const bool depth = st.depthTest && hasDepth;
  if (!bounds && !stencil && !depth) return coverage;
  uint32_t passed = coverage;
  if (!bounds && !stencil && ds.depthFormat == DepthFormat::D32SFloat) {
    // Depth alone on D32_SFLOAT (the common case): the stored float compared and replaced as is.
    const uint32_t bytes = ds.depthTexelBytes;  // 8 with D32_SFLOAT_S8_UINT
    uint8_t* pixel = texel(ds.depth, bytes, ctx.layer, x, y, 0);
    for (uint32_t sm = coverage; sm; sm &= sm - 1) {
      const uint32_t s = uint32_t(std::countr_zero(sm));
      float old;
      std::memcpy(&old, pixel + bytes * s, 4);
      if (!compare(st.depthCompare, z[s], old))
        passed &= ~(1u << s);
      else if (st.depthWrite)
        std::memcpy(pixel + bytes * s, &z[s], 4);
    }
    return passed;
  }
  const StencilFace& face = front ? st.front : st.back;
  for (uint32_t sm = coverage; sm; sm &= sm - 1) {
    const uint32_t s = uint32_t(std::countr_zero(sm));
    uint8_t* dp = hasDepth ? texel(ds.depth, ds.depthTexelBytes, ctx.layer, x, y, s) : nullptr;
    uint8_t* sp = hasStencil ? texel(ds.stencil, ds.stencilTexelBytes, ctx.layer, x, y, s) + ds.stencilOffset : nullptr;
    if (bounds) {
      // Depth bounds test: the stored depth within [minDepthBounds, maxDepthBounds].
      const float stored = readDepth(ds.depthFormat, dp).f;
      if (!(stored >= st.minDepthBounds && stored <= st.maxDepthBounds)) {
        passed &= ~(1u << s);
        continue;
      }
    }
    if (stencil) {
      const uint32_t ref = face.reference & face.compareMask, stored = *sp & face.compareMask;
      if (!compare(face.compareOp, ref, stored)) {
        applyStencil(sp, face, face.failOp);
        passed &= ~(1u << s);
        continue;
      }
    }
    if (depth) {
      const DepthValue v = toStored(ds.depthFormat, z[s]);
      const DepthValue old = readDepth(ds.depthFormat, dp);
      const bool pass = ds.depthFormat == DepthFormat::D32SFloat ? compare(st.depthCompare, v.f, old.f)
                                                                 : compare(st.depthCompare, v.u, old.u);
      if (!pass) {
        if (stencil) applyStencil(sp, face, face.depthFailOp);
        passed &= ~(1u << s);
        continue;
      }
      if (st.depthWrite) writeDepth(ds.depthFormat, dp, v);
    }
    if (stencil) applyStencil(sp, face, face.passOp);
  }
  return passed;
}

namespace {

// ------------------------------------------------------------------------------------------------ the quad paths

std::atomic<bool> quadPaths{true};

// The general paths, lane by lane (any format, sample count and state).
uint32_t depthStencilLanes(const DrawContext& ctx, bool front, int32_t qx, int32_t qy, uint32_t cov[4],
                           const float (*z)[4]) {
  uint32_t any = 0;
  for (uint32_t l = 0; l < 4; ++l) {
    if (!cov[l]) continue;
    float lane[4];  // the lane's depth at each sample
    for (uint32_t s = 0; s < ctx.samples; ++s) lane[s] = z[s][l];
    any |= cov[l] = depthStencilTests(ctx, front, qx + int32_t(l & 1), qy + int32_t(l >> 1), cov[l], lane);
  }
  return any;
}

uint32_t noDepthStencil(const DrawContext&, bool, int32_t, int32_t, uint32_t cov[4], const float (*)[4]) {
  return cov[0] | cov[1] | cov[2] | cov[3];
}

void colorLanes(const DrawContext& ctx, uint32_t i, const FragmentQuad& q, const uint32_t cov[4]) {
  for (uint32_t l = 0; l < 4; ++l)
    if (cov[l]) writeAttachment(ctx, q, l, i, q.x + int32_t(l & 1), q.y + int32_t(l >> 1), cov[l]);
}

void colorUnorm8Lanes(const DrawContext& ctx, uint32_t i, const FragmentQuad& q, const uint32_t cov[4]) {
  uint32_t mask;
  unorm8Path(ctx, i, &mask);
  const Unorm8Target t(ctx, i, mask);
  for (uint32_t l = 0; l < 4; ++l)
    if (cov[l]) writeUnorm8(ctx, t, q, l, i, q.x + int32_t(l & 1), q.y + int32_t(l >> 1), cov[l]);
}

// Depth alone (no stencil, no bounds), one sample: the format, compare op and write fixed at compile time, the four
// lanes in one call. Unorm formats convert, compare as stored and keep X8D24's top byte as depthStencilTests does
// (toStored, readDepth, writeDepth); D32_SFLOAT compares the stored float, and a quad whose four lanes are covered
// compares as one vector (its texels are two pairs of adjacent floats when the texel is 4 bytes).
template <DepthFormat kFmt, CompareOp kOp, bool kWrite>
uint32_t depthQuad(const DrawContext& ctx, bool, int32_t qx, int32_t qy, uint32_t cov[4], const float (*z)[4]) {
  const DepthStencilTarget& ds = ctx.target->depthStencil;
  const size_t bytes = ds.depthTexelBytes, pitch = ds.depth.rowPitch;
  uint8_t* p0 = texel(ds.depth, uint32_t(bytes), ctx.layer, qx, qy, 0);
  if (kFmt == DepthFormat::D32SFloat && (bytes == 4 || bytes == 8) && cov[0] && cov[1] && cov[2] && cov[3]) {
    // A row's two texels: two floats (D32_SFLOAT), or depth, stencil word, depth, stencil word (D32_SFLOAT_S8_UINT).
    using Float2 = float __attribute__((vector_size(8)));
    Float4 zq;
    std::memcpy(&zq, z[0], 16);
    Float4 old;
    Float4 rows[2];  // the 8-byte texels' rows as read
    if (bytes == 4) {
      Float2 top, bottom;
      std::memcpy(&top, p0, 8);
      std::memcpy(&bottom, p0 + pitch, 8);
      old = __builtin_shufflevector(top, bottom, 0, 1, 2, 3);
    } else {
      std::memcpy(&rows[0], p0, 16);
      std::memcpy(&rows[1], p0 + pitch, 16);
      old = __builtin_shufflevector(rows[0], rows[1], 0, 2, 4, 6);
    }
    const Int4 pass = compare(kOp, zq, old);
    if (kWrite) {
      // Failing lanes get their old bits back (a NaN stays the same NaN), and the stencil words theirs: the tile is
      // this worker's alone.
      const Float4 v = pass ? zq : old;
      if (bytes == 4) {
        const Float2 vTop = __builtin_shufflevector(v, v, 0, 1), vBottom = __builtin_shufflevector(v, v, 2, 3);
        std::memcpy(p0, &vTop, 8);
        std::memcpy(p0 + pitch, &vBottom, 8);
      } else {
        const Float4 top = __builtin_shufflevector(v, rows[0], 0, 5, 1, 7);
        const Float4 bottom = __builtin_shufflevector(v, rows[1], 2, 5, 3, 7);
        std::memcpy(p0, &top, 16);
        std::memcpy(p0 + pitch, &bottom, 16);
      }
    }
    // The passing lanes' coverage kept, the union of the four by two folds.
    Int4 c;
    std::memcpy(&c, cov, 16);
    c &= pass;
    std::memcpy(cov, &c, 16);
    c |= __builtin_shufflevector(c, c, 2, 3, 0, 1);
    c |= __builtin_shufflevector(c, c, 1, 0, 3, 2);
    return uint32_t(c[0]);
  }
  uint32_t any = 0;
  for (uint32_t l = 0; l < 4; ++l) {
    if (!cov[l]) continue;
    uint8_t* p = p0 + (l & 1) * bytes + (l >> 1) * pitch;
    bool pass;
    if constexpr (kFmt == DepthFormat::D32SFloat) {
      float old;
      std::memcpy(&old, p, 4);
      pass = compare(kOp, z[0][l], old);
      if (pass && kWrite) std::memcpy(p, &z[0][l], 4);
    } else {
      const DepthValue v = toStored(kFmt, z[0][l]);
      pass = compare(kOp, v.u, readDepth(kFmt, p).u);
      if (pass && kWrite) writeDepth(kFmt, p, v);
    }
    if (pass) {
      any |= cov[l];
    } else {
      cov[l] = 0;
    }
  }
  return any;
}

template <DepthFormat kFmt, bool kWrite>
auto depthQuadFor(CompareOp op) -> decltype(&depthQuad<kFmt, CompareOp::Less, kWrite>) {
  switch (op) {
    case CompareOp::Never: return depthQuad<kFmt, CompareOp::Never, kWrite>;
    case CompareOp::Less: return depthQuad<kFmt, CompareOp::Less, kWrite>;
    case CompareOp::Equal: return depthQuad<kFmt, CompareOp::Equal, kWrite>;
    case CompareOp::LessOrEqual: return depthQuad<kFmt, CompareOp::LessOrEqual, kWrite>;
    case CompareOp::Greater: return depthQuad<kFmt, CompareOp::Greater, kWrite>;
    case CompareOp::NotEqual: return depthQuad<kFmt, CompareOp::NotEqual, kWrite>;
    case CompareOp::GreaterOrEqual: return depthQuad<kFmt, CompareOp::GreaterOrEqual, kWrite>;
    case CompareOp::Always: return depthQuad<kFmt, CompareOp::Always, kWrite>;
  }
  return nullptr;
}

template <DepthFormat kFmt>
auto depthQuadFor(CompareOp op, bool write) -> decltype(&depthQuad<kFmt, CompareOp::Less, true>) {
  return write ? depthQuadFor<kFmt, true>(op) : depthQuadFor<kFmt, false>(op);
}

// The 8-bit UNorm layouts with one sample, the quad's four pixels at once with the components in separate vectors
// (R of the four lanes, G, ...): the same float operations per component, in the same order, as writeUnorm8 and the
// general path (blend factors, blend op, clamps, write mask) and the same codecs, so the same bytes.
struct Quad4 {
  Float4 c[4];  // per component, per lane
};

// A quad's colour output as FragmentQuad holds it (per component, the four lanes) to component vectors.
inline Quad4 components(const uint32_t (&c)[4][4]) {
  Quad4 q;
  std::memcpy(q.c, c, sizeof q.c);
  return q;
}

// Component c of blend factor f for the four lanes (blendFactor's cases; k holds the constants splatted).
__attribute__((always_inline)) inline Float4 factorQuad(BlendFactor f, int c, const Quad4& s, const Quad4& s1,
                                                        const Quad4& d, const Quad4& k) {
  switch (f) {
    case BlendFactor::Zero: return splat(0);
    case BlendFactor::One: return splat(1);
    case BlendFactor::SrcColor: return s.c[c];
    case BlendFactor::OneMinusSrcColor: return 1.0f - s.c[c];
    case BlendFactor::DstColor: return d.c[c];
    case BlendFactor::OneMinusDstColor: return 1.0f - d.c[c];
    case BlendFactor::SrcAlpha: return s.c[3];
    case BlendFactor::OneMinusSrcAlpha: return 1.0f - s.c[3];
    case BlendFactor::DstAlpha: return d.c[3];
    case BlendFactor::OneMinusDstAlpha: return 1.0f - d.c[3];
    case BlendFactor::ConstantColor: return k.c[c];
    case BlendFactor::OneMinusConstantColor: return 1.0f - k.c[c];
    case BlendFactor::ConstantAlpha: return k.c[3];
    case BlendFactor::OneMinusConstantAlpha: return 1.0f - k.c[3];
    case BlendFactor::SrcAlphaSaturate: {
      if (c == 3) return splat(1);
      const Float4 a = s.c[3], b = 1.0f - d.c[3];
      return b < a ? b : a;  // std::min(a, b)
    }
    case BlendFactor::Src1Color: return s1.c[c];
    case BlendFactor::OneMinusSrc1Color: return 1.0f - s1.c[c];
    case BlendFactor::Src1Alpha: return s1.c[3];
    case BlendFactor::OneMinusSrc1Alpha: return 1.0f - s1.c[3];
  }
  return splat(0);
}

inline bool readsSource1(BlendFactor f) {
  return f == BlendFactor::Src1Color || f == BlendFactor::OneMinusSrc1Color || f == BlendFactor::Src1Alpha ||
         f == BlendFactor::OneMinusSrc1Alpha;
}

// The blend equations common enough to get code of their own (the factors and ops known at compile time); kShape -1:
// the attachment's, read at run time.
struct BlendShape {
  BlendFactor srcColor, dstColor, srcAlpha, dstAlpha;
  BlendOp colorOp, alphaOp;
};
constexpr BlendShape kBlendShapes[] = {
    // Straight alpha ("over"), alpha accumulated as coverage.
    {BlendFactor::SrcAlpha, BlendFactor::OneMinusSrcAlpha, BlendFactor::One, BlendFactor::OneMinusSrcAlpha,
     BlendOp::Add, BlendOp::Add},
    // Straight alpha on all four components.
    {BlendFactor::SrcAlpha, BlendFactor::OneMinusSrcAlpha, BlendFactor::SrcAlpha, BlendFactor::OneMinusSrcAlpha,
     BlendOp::Add, BlendOp::Add},
    // Premultiplied alpha.
    {BlendFactor::One, BlendFactor::OneMinusSrcAlpha, BlendFactor::One, BlendFactor::OneMinusSrcAlpha, BlendOp::Add,
     BlendOp::Add},
    // Additive.
    {BlendFactor::One, BlendFactor::One, BlendFactor::One, BlendFactor::One, BlendOp::Add, BlendOp::Add},
};

static_assert(std::size(kBlendShapes) == 4, "unorm8QuadFor instantiates each shape");

inline int blendShapeOf(const BlendAttachment& b) {
  for (int i = 0; i < int(std::size(kBlendShapes)); ++i) {
    const BlendShape& k = kBlendShapes[i];
    if (b.srcColor == k.srcColor && b.dstColor == k.dstColor && b.srcAlpha == k.srcAlpha && b.dstAlpha == k.dstAlpha &&
        b.colorOp == k.colorOp && b.alphaOp == k.alphaOp)
      return i;
  }
  return -1;
}

// What a blend of attachment i reads beside the quad's colour and the destination: its equation (kShape's, or the
// attachment's when kShape is -1), the dual-source colour and the blend constants, each clamped to [0, 1].
struct BlendOperands {
  BlendShape shape;
  Quad4 s1, k;
};

// kClamp: a normalized format's (the dual-source colour and the constants clamped); a float format's are as given.
template <int kShape, bool kClamp = true>
BlendOperands blendOperands(const DrawContext& ctx, uint32_t i, const FragmentQuad& q) {
  const BlendAttachment& ba = ctx.state->blend[i];
  BlendOperands o{kShape >= 0 ? kBlendShapes[kShape]
                              : BlendShape{ba.srcColor, ba.dstColor, ba.srcAlpha, ba.dstAlpha, ba.colorOp, ba.alphaOp},
                  {},
                  {}};
  const BlendShape& b = o.shape;
  if (readsSource1(b.srcColor) || readsSource1(b.dstColor) || readsSource1(b.srcAlpha) || readsSource1(b.dstAlpha)) {
    o.s1 = components(q.color1);
    if (kClamp)
      for (Float4& v : o.s1.c) v = clamp01(v);
  }
  for (int c = 0; c < 4; ++c)
    o.k.c[c] = kClamp ? clamp01(splat(ctx.state->blendConstants[c])) : splat(ctx.state->blendConstants[c]);
  return o;
}

using UInt4 = uint32_t __attribute__((vector_size(16)));
using UInt2 = uint32_t __attribute__((vector_size(8)));

// The addresses of a quad's four 32-bit texels in `surf` (lane l's at lane[l]; pixel rows lane[0..1], lane[2..3]).
struct QuadTexels {
  uint8_t* lane[4];
  uint8_t* operator[](uint32_t l) const { return lane[l]; }
};

inline QuadTexels quadTexels(const Surface& surf, uint32_t layer, const FragmentQuad& q) {
  uint8_t* const p0 = texel(surf, 4, layer, q.x, q.y, 0);
  return {{p0, p0 + 4, p0 + surf.rowPitch, p0 + surf.rowPitch + 4}};
}

// The quad's four texels, the uncovered ones 0.
__attribute__((always_inline)) inline UInt4 readQuadTexels(const QuadTexels& lane, const uint32_t cov[4], bool full) {
  if (full) {
    // The two rows straight into the vector (two 8-byte loads): through a 16-byte array in memory, the load of the
    // whole after the two smaller stores could not be forwarded from them and stalled.
    UInt2 top, bottom;
    std::memcpy(&top, lane[0], 8), std::memcpy(&bottom, lane[2], 8);
    return __builtin_shufflevector(top, bottom, 0, 1, 2, 3);
  }
  uint32_t w[4] = {0, 0, 0, 0};
  for (uint32_t l = 0; l < 4; ++l)
    if (cov[l]) std::memcpy(&w[l], lane[l], 4);
  UInt4 words;
  std::memcpy(&words, w, 16);
  return words;
}

// Lane l's texel of `out` to lane[l] where cov[l] (all four: `full`).
__attribute__((always_inline)) inline void writeQuadTexels(const QuadTexels& lane, const uint32_t cov[4], bool full,
                                                           UInt4 out) {
  if (full) {
    const UInt2 top = __builtin_shufflevector(out, out, 0, 1), bottom = __builtin_shufflevector(out, out, 2, 3);
    std::memcpy(lane[0], &top, 8), std::memcpy(lane[2], &bottom, 8);
    return;
  }
  uint32_t w[4];
  std::memcpy(w, &out, 16);
  for (uint32_t l = 0; l < 4; ++l)
    if (cov[l]) std::memcpy(lane[l], &w[l], 4);
}

// An sRGB layout's colour component at `shift` of the four texels `words`, decoded by abi/srgb8.hpp's table (the
// runtime's decode), and four linear values encoded by its encode (NaN 0, clamped): decodeColor's and encodeColor's.
__attribute__((always_inline)) inline Float4 srgbDecode4(const abi::Srgb8Tables& t, UInt4 words, int shift) {
  return Float4{t.decode[words[0] >> shift & 0xFF], t.decode[words[1] >> shift & 0xFF],
                t.decode[words[2] >> shift & 0xFF], t.decode[words[3] >> shift & 0xFF]};
}
//
// The encode four at a time, in float arithmetic with the table for the rare lanes it cannot decide: 255 times the
// sRGB curve approximated (x^(5/12) as m^(5/12) 2^(5e/12) for x = m 2^e: a degree-6 polynomial in m - 1.5 and a
// table of the nine powers of 2^(5/12) the curve's power segment needs, the polynomial in Estrin's form; 12.92 x below
// 0.0031308), within 1.2e-4 of the exact value for every float in [2^-13, 1) (measured against a long double pow),
// then rounded; where the approximation lies within 2^-10 of a half (about 0.2 % of values) the byte could be either
// neighbour, and the table decides. So the same bytes as abi::Srgb8Tables::encode, which
// `RasterSrgb8.VectorEncodeIsTheTablesForEveryFloat` checks for every float of [2^-13, 1).
constexpr float kSrgbPoly[7] = {0x1.2f1e22p+0f, 0x1.50ccccp-2f, -0x1.05f58cp-4f, 0x1.6f6564p-6f,
                                -0x1.3c0f1p-7f, 0x1.571c1cp-8f, -0x1.60c89ep-9f};
constexpr float kSrgbScale[9] = {0x1.306fep-4f, 0x1.965feap-4f, 0x1.0f38fap-3f, 0x1.6a09e6p-3f, 0x1.e3437ep-3f,
                                 0x1.428a3p-2f, 0x1.ae89fap-2f, 0x1.1f59acp-1f, 0x1.7f910ep-1f};  // 2^(5e/12), e -9..-1

inline uint32_t laneMask4(Int4 m) {  // the lanes' sign bits, lane k at bit k
#if defined(__SSE2__)
  return uint32_t(_mm_movemask_ps(_mm_castsi128_ps(__m128i(m))));
#else
  return uint32_t(m[0] < 0) | uint32_t(m[1] < 0) << 1 | uint32_t(m[2] < 0) << 2 | uint32_t(m[3] < 0) << 3;
#endif
}

__attribute__((always_inline)) inline UInt4 srgbEncode4(const abi::Srgb8Tables& t, Float4 x) {
  const Int4 bits = (Int4)x;
  const Float4 u = (Float4)((bits & 0x007FFFFF) | 0x3F800000) - 1.5f;  // m - 1.5
  const Float4 u2 = u * u;
  const Float4 p = (kSrgbPoly[0] + kSrgbPoly[1] * u) + u2 * (kSrgbPoly[2] + kSrgbPoly[3] * u) +
                   (u2 * u2) * (kSrgbPoly[4] + kSrgbPoly[5] * u + kSrgbPoly[6] * u2);  // Estrin's form
  Int4 e = (bits >> 23 & 0xFF) - (127 - 9);
  e = e < 0 ? Int4{} : e > 8 ? Int4{} + 8 : e;
  const Float4 scale = {kSrgbScale[e[0]], kSrgbScale[e[1]], kSrgbScale[e[2]], kSrgbScale[e[3]]};
  Float4 v = (1.055f * (p * scale) - 0.055f) * 255.0f;
  v = x <= 0.0031308f ? x * (12.92f * 255.0f) : v;
  // Rounded (v + 1/2 truncated); undecided where the fraction of v + 1/2 is within 2^-10 of 0 or 1.
  const Float4 r = v + 0.5f;
  const Int4 code = __builtin_convertvector(r, Int4);
  const Float4 f = r - __builtin_convertvector(code, Float4);
  const Int4 inRange = x >= 0x1p-13f && x < 1.0f;  // else 0 (NaN too) or 255
  UInt4 out = UInt4(inRange ? code : x >= 1.0f ? Int4{} + 255 : Int4{});
  const Int4 undecided = inRange && (f < 0x1p-10f || f > 1.0f - 0x1p-10f);
  if (__builtin_expect(laneMask4(undecided) != 0, 0))
    for (int l = 0; l < 4; ++l)
      if (undecided[l]) out[l] = t.encode(x[l]);
  return out;
}

// kSrgb: an sRGB layout (the colour components decoded and encoded as sRGB, alpha as UNorm).
template <bool kBgra, bool kBlend, bool kReadDst, int kShape = -1, bool kSrgb = false>
void colorUnorm8Quad(const DrawContext& ctx, uint32_t i, const FragmentQuad& q, const uint32_t cov[4]) {
  const BlendAttachment& ba = ctx.state->blend[i];
  const QuadTexels lane = quadTexels(ctx.target->color[i], ctx.layer, q);
  Quad4 s = components(q.color[i]);
  // The clamps to [0, 1] of the source and of the blend result (clampToFormat) are left to the encode's saturate
  // where nothing else reads the value: saturate(clamp01(v)) is saturate(v) (a NaN that clamp01 keeps, saturate makes
  // 0), so the bytes are the same.
  if (kBlend)
    for (Float4& v : s.c) v = clamp01(v);
  Quad4 d{};
  const bool full = cov[0] && cov[1] && cov[2] && cov[3];  // most quads: two 8-byte rows
  if (kReadDst) {
    const UInt4 words = readQuadTexels(lane, cov, full);
    for (int c = 0; c < 4; ++c) {
      const int shift = 8 * (kBgra && c != 1 && c != 3 ? 2 - c : c);
      if (kSrgb && c < 3)
        d.c[c] = srgbDecode4(abi::srgb8Tables(), words, shift);
      else
        d.c[c] = __builtin_convertvector(Int4((words >> shift) & 0xFF), Float4) / 255.0f;  // 0..255: signed
    }
  }
  Quad4 r = s;
  if (kBlend) {
    const BlendOperands o = blendOperands<kShape>(ctx, i, q);
    const BlendShape& b = o.shape;
    const Quad4 &s1 = o.s1, &k = o.k;
    for (int c = 0; c < 4; ++c) {
      const bool alpha = c == 3;
      const Float4 sf = factorQuad(alpha ? b.srcAlpha : b.srcColor, c, s, s1, d, k);
      const Float4 df = factorQuad(alpha ? b.dstAlpha : b.dstColor, c, s, s1, d, k);
      r.c[c] = blendOp4(alpha ? b.alphaOp : b.colorOp, s.c[c], sf, d.c[c], df);  // clamped by the encode
    }
  }
  const uint32_t mask = ba.writeMask & ctx.target->colorFormat[i].componentMask;
  UInt4 out = {0, 0, 0, 0};
  for (int c = 0; c < 4; ++c) {
    Float4 v = kReadDst && !(mask >> c & 1) ? d.c[c] : r.c[c];
    const int shift = 8 * (kBgra && c != 1 && c != 3 ? 2 - c : c);
    out |= (kSrgb && c < 3 ? srgbEncode4(abi::srgb8Tables(), v) : UInt4(unorm8Bytes(saturate(v)))) << shift;
  }
  writeQuadTexels(lane, cov, full, out);
}

// R16G16B16A16_SFLOAT with one sample (ColorFormat::rgba16Float), a whole quad: the destination decoded and the
// result encoded by `codec` (the format's codecs, lane by lane, in the baseline copy; F16C conversions in the AVX2
// copy below), the source, the blend and the write mask as the general path computes them for a float format (no
// clamps: writeAttachment's clampToFormat leaves float formats as they are), per component in the same order.
// `Codec` decodes the covered lanes' texels into components (decode(lane, cov, d)) and encodes them back
// (encode(r, lane, cov)).
template <bool kBlend, bool kReadDst, int kShape, class Codec>
__attribute__((always_inline)) inline void half4Quad(const DrawContext& ctx, uint32_t i, const FragmentQuad& q,
                                                     const uint32_t cov[4], const Codec& codec) {
  const BlendAttachment& ba = ctx.state->blend[i];
  const Surface& surf = ctx.target->color[i];
  uint8_t* const p0 = texel(surf, 8, ctx.layer, q.x, q.y, 0);
  uint8_t* const lane[4] = {p0, p0 + 8, p0 + surf.rowPitch, p0 + surf.rowPitch + 8};
  const Quad4 s = components(q.color[i]);
  Quad4 d{};
  if (kReadDst) codec.decode(lane, cov, d);
  Quad4 r = s;
  if (kBlend) {
    const BlendOperands o = blendOperands<kShape, false>(ctx, i, q);
    const BlendShape& b = o.shape;
    for (int c = 0; c < 4; ++c) {
      const bool alpha = c == 3;
      const Float4 sf = factorQuad(alpha ? b.srcAlpha : b.srcColor, c, s, o.s1, d, o.k);
      const Float4 df = factorQuad(alpha ? b.dstAlpha : b.dstColor, c, s, o.s1, d, o.k);
      r.c[c] = blendOp4(alpha ? b.alphaOp : b.colorOp, s.c[c], sf, d.c[c], df);
    }
  }
  const uint32_t mask = ba.writeMask & ctx.target->colorFormat[i].componentMask;
  if (kReadDst)
    for (int c = 0; c < 4; ++c)
      if (!(mask >> c & 1)) r.c[c] = d.c[c];
  codec.encode(r, lane, cov);
}

// The baseline copy's codec: the format's own, a texel at a time.
struct Half4Codec {
  const ColorFormat* fmt;
  void decode(uint8_t* const lane[4], const uint32_t cov[4], Quad4& d) const {
    for (int l = 0; l < 4; ++l) {
      if (!cov[l]) continue;
      uint32_t w[4];
      fmt->decode(fmt->format, lane[l], w);
      for (int c = 0; c < 4; ++c) d.c[c][l] = asFloat(w[c]);
    }
  }
  void encode(const Quad4& r, uint8_t* const lane[4], const uint32_t cov[4]) const {
    for (int l = 0; l < 4; ++l) {
      if (!cov[l]) continue;
      const uint32_t w[4] = {asWord(r.c[0][l]), asWord(r.c[1][l]), asWord(r.c[2][l]), asWord(r.c[3][l])};
      fmt->encode(fmt->format, w, lane[l]);
    }
  }
};

template <bool kBlend, bool kReadDst, int kShape = -1>
void colorHalf4Quad(const DrawContext& ctx, uint32_t i, const FragmentQuad& q, const uint32_t cov[4]) {
  half4Quad<kBlend, kReadDst, kShape>(ctx, i, q, cov, Half4Codec{&ctx.target->colorFormat[i]});
}

#if defined(__x86_64__)
// colorUnorm8Quad for AVX2: two components in each 256-bit vector (R and G of the four lanes, then B and A), so the
// decode, the blend and the encode take half the instructions. The same float operations per element in the same
// order (no FMA: the target has none, so nothing is contracted), the same clamps (vmaxps/vminps take their second
// operand when unordered, as maxps/minps) and the same encode (times 255 in float, rounded in the current mode by
// vcvtps2dq): the same bytes as the baseline copy (RasterQuadPath compares them).
VKRT_AVX2_BEGIN
using Float8 = float __attribute__((vector_size(32)));
using Int8 = int32_t __attribute__((vector_size(32)));
using UInt8 = uint32_t __attribute__((vector_size(32)));

inline Float8 join(Float4 lo, Float4 hi) { return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7); }
inline Float4 half(Float8 v, int h) {
  return h ? __builtin_shufflevector(v, v, 4, 5, 6, 7) : __builtin_shufflevector(v, v, 0, 1, 2, 3);
}
inline Float8 clamp01x8(Float8 v) {
  return Float8(_mm256_min_ps(_mm256_set1_ps(1.0f), _mm256_max_ps(_mm256_setzero_ps(), __m256(v))));
}
inline Float8 saturate8(Float8 v) {
  return Float8(_mm256_min_ps(_mm256_max_ps(__m256(v), _mm256_setzero_ps()), _mm256_set1_ps(1.0f)));
}
// unorm8Bytes of all eight.
inline Int8 unorm8Bytes8(Float8 v) {
  return Int8(_mm256_cvtps_epi32(_mm256_mul_ps(__m256(v), _mm256_set1_ps(255.0f))));
}

// srgbEncode4 on eight values: the same float operations (no FMA in this target), so the same decisions, with
// kSrgbScale read by a permute (entries 1..8) and a blend (entry 0) instead of lane by lane.
__attribute__((always_inline)) inline UInt8 srgbEncode8(const abi::Srgb8Tables& t, Float8 x) {
  const Int8 bits = (Int8)x;
  const Float8 u = (Float8)((bits & 0x007FFFFF) | 0x3F800000) - 1.5f;
  const Float8 u2 = u * u;
  const Float8 p = (kSrgbPoly[0] + kSrgbPoly[1] * u) + u2 * (kSrgbPoly[2] + kSrgbPoly[3] * u) +
                   (u2 * u2) * (kSrgbPoly[4] + kSrgbPoly[5] * u + kSrgbPoly[6] * u2);  // Estrin's form
  Int8 e = (bits >> 23 & 0xFF) - (127 - 9);
  e = e < 0 ? Int8{} : e > 8 ? Int8{} + 8 : e;
  Float8 scale = Float8(_mm256_permutevar8x32_ps(_mm256_loadu_ps(kSrgbScale + 1), __m256i(e - 1)));
  scale = e == 0 ? Float8{} + kSrgbScale[0] : scale;
  Float8 v = (1.055f * (p * scale) - 0.055f) * 255.0f;
  v = x <= 0.0031308f ? x * (12.92f * 255.0f) : v;
  const Float8 r = v + 0.5f;
  const Int8 code = __builtin_convertvector(r, Int8);
  const Float8 f = r - __builtin_convertvector(code, Float8);
  const Int8 inRange = x >= 0x1p-13f && x < 1.0f;
  UInt8 out = UInt8(inRange ? code : x >= 1.0f ? Int8{} + 255 : Int8{});
  const Int8 undecided = inRange && (f < 0x1p-10f || f > 1.0f - 0x1p-10f);
  if (__builtin_expect(_mm256_movemask_ps(_mm256_castsi256_ps(__m256i(undecided))) != 0, 0))
    for (int l = 0; l < 8; ++l)
      if (undecided[l]) out[l] = t.encode(x[l]);
  return out;
}

void encodeSrgb8OctetsAvx2(const float* in, uint32_t* out, size_t n) {
  const abi::Srgb8Tables& t = abi::srgb8Tables();
  for (size_t i = 0; i + 8 <= n; i += 8) {
    Float8 x;
    std::memcpy(&x, in + i, 32);
    const UInt8 v = srgbEncode8(t, x);
    std::memcpy(out + i, &v, 32);
  }
}

template <bool kBgra, bool kBlend, bool kReadDst, int kShape = -1, bool kSrgb = false>
void colorUnorm8QuadAvx2(const DrawContext& ctx, uint32_t i, const FragmentQuad& q, const uint32_t cov[4]) {
  const BlendAttachment& ba = ctx.state->blend[i];
  const QuadTexels lane = quadTexels(ctx.target->color[i], ctx.layer, q);
  // Component c's byte in a word.
  constexpr auto shiftOf = [](int c) { return 8 * (kBgra && c != 1 && c != 3 ? 2 - c : c); };
  const UInt8 shift[2] = {
      UInt8{} + uint32_t(shiftOf(0)) + UInt8{0, 0, 0, 0, 1, 1, 1, 1} * uint32_t(shiftOf(1) - shiftOf(0)),
      UInt8{} + uint32_t(shiftOf(2)) + UInt8{0, 0, 0, 0, 1, 1, 1, 1} * uint32_t(shiftOf(3) - shiftOf(2))};
  // Each component's four lanes with a load of its own: the shader stored them one 16-byte vector at a time, and a
  // 32-byte load over two such stores cannot be forwarded from them (it waited for both to reach the cache: a sixth of
  // the blended overlays' time).
  const Quad4 c = components(q.color[i]);
  Float8 s[2] = {join(c.c[0], c.c[1]), join(c.c[2], c.c[3])};
  if (kBlend)
    for (Float8& v : s) v = clamp01x8(v);
  const bool full = cov[0] && cov[1] && cov[2] && cov[3];
  Float8 d[2] = {};
  if (kReadDst) {
    const UInt4 words = readQuadTexels(lane, cov, full);
    const UInt8 both = __builtin_shufflevector(words, words, 0, 1, 2, 3, 0, 1, 2, 3);
    for (int h = 0; h < 2; ++h) d[h] = __builtin_convertvector(Int8((both >> shift[h]) & 0xFF), Float8) / 255.0f;
    if (kSrgb) {  // R, G and B by the table (the baseline copy's srgbDecode4)
      const abi::Srgb8Tables& t = abi::srgb8Tables();
      d[0] = join(srgbDecode4(t, words, shiftOf(0)), srgbDecode4(t, words, shiftOf(1)));
      d[1] = join(srgbDecode4(t, words, shiftOf(2)), half(d[1], 1));
    }
  }
  Float8 r[2] = {s[0], s[1]};
  if (kBlend) {
    const BlendOperands o = blendOperands<kShape>(ctx, i, q);
    const BlendShape& b = o.shape;
    const Quad4 &s1 = o.s1, &k = o.k;
    // The factors per component, as the baseline copy computes them (factorQuad on the components' vectors).
    const Quad4 sq{{half(s[0], 0), half(s[0], 1), half(s[1], 0), half(s[1], 1)}};
    const Quad4 dq{{half(d[0], 0), half(d[0], 1), half(d[1], 0), half(d[1], 1)}};
    for (int h = 0; h < 2; ++h) {
      const int c0 = 2 * h, c1 = 2 * h + 1;
      const bool alpha1 = c1 == 3;  // the second component of the second pair is A
      const Float8 sf = join(factorQuad(b.srcColor, c0, sq, s1, dq, k),
                             factorQuad(alpha1 ? b.srcAlpha : b.srcColor, c1, sq, s1, dq, k));
      const Float8 df = join(factorQuad(b.dstColor, c0, sq, s1, dq, k),
                             factorQuad(alpha1 ? b.dstAlpha : b.dstColor, c1, sq, s1, dq, k));
      const BlendOp op0 = b.colorOp, op1 = alpha1 ? b.alphaOp : b.colorOp;
      if (op0 == op1 && op0 == BlendOp::Add) {
        r[h] = s[h] * sf + d[h] * df;  // blendOp4's Add
      } else {
        r[h] = join(blendOp4(op0, half(s[h], 0), half(sf, 0), half(d[h], 0), half(df, 0)),
                    blendOp4(op1, half(s[h], 1), half(sf, 1), half(d[h], 1), half(df, 1)));
      }
    }
  }
  const uint32_t mask = ba.writeMask & ctx.target->colorFormat[i].componentMask;
  UInt8 out8 = {};
  for (int h = 0; h < 2; ++h) {
    Float8 v = r[h];
    if (kReadDst && mask != 0xF) {
      const Int8 keep = Int8{} + Int8{0, 0, 0, 0, 1, 1, 1, 1} * int32_t(!(mask >> (2 * h + 1) & 1)) +
                        Int8{1, 1, 1, 1, 0, 0, 0, 0} * int32_t(!(mask >> (2 * h) & 1));
      v = keep != 0 ? d[h] : v;
    }
    UInt8 bytes;
    if (kSrgb) {  // R, G and B by abi/srgb8.hpp's encode (srgbEncode8, the baseline copy's srgbEncode4), A as UNorm
      const UInt8 colour = srgbEncode8(abi::srgb8Tables(), v);
      const UInt8 alphaLanes = {0, 0, 0, 0, ~0u, ~0u, ~0u, ~0u};  // the second pair's A
      bytes = h ? (alphaLanes & UInt8(unorm8Bytes8(saturate8(v)))) | (~alphaLanes & colour) : colour;
    } else {
      bytes = UInt8(unorm8Bytes8(saturate8(v)));
    }
    out8 |= bytes << shift[h];
  }
  writeQuadTexels(lane, cov, full,
                  __builtin_shufflevector(out8, out8, 0, 1, 2, 3) | __builtin_shufflevector(out8, out8, 4, 5, 6, 7));
}
VKRT_AVX2_END
#endif

#if defined(__x86_64__)
// The AVX2 copy's codec for half4Quad: F16C's conversions of the two rows (two texels, eight halves, each), the same
// values as the format's codecs: exact widening; narrowing rounded to nearest even, overflow to infinity (the codec's
// 65520 and up); a NaN made the codec's 0x7E00 (F16C keeps its sign and payload; those of a decoded NaN reach nothing
// but the encode, which replaces them).
struct Half4CodecF16c {
  __attribute__((target("avx2,f16c"))) void decode(uint8_t* const lane[4], const uint32_t cov[4], Quad4& d) const {
    __m128i row[2];
    for (int h = 0; h < 2; ++h) {
      if (cov[2 * h] && cov[2 * h + 1]) {
        row[h] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(lane[2 * h]));
      } else {
        const __m128i a = cov[2 * h] ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(lane[2 * h])) : __m128i{};
        const __m128i b =
            cov[2 * h + 1] ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(lane[2 * h + 1])) : __m128i{};
        row[h] = _mm_unpacklo_epi64(a, b);
      }
    }
    const __m256 a = _mm256_cvtph_ps(row[0]), b = _mm256_cvtph_ps(row[1]);  // lanes 0, 1 and 2, 3: r g b a r g b a
    // To components: c of lane l.
    const __m256 lo = _mm256_permute2f128_ps(a, b, 0x20), hi = _mm256_permute2f128_ps(a, b, 0x31);  // l0 l2 | l1 l3
    const __m256 t0 = _mm256_unpacklo_ps(lo, hi), t1 = _mm256_unpackhi_ps(lo, hi);  // r0 r1 g0 g1 | r2 r3 g2 g3 ...
    const Float8 u0 = Float8(t0), u1 = Float8(t1);
    d.c[0] = Float4{u0[0], u0[1], u0[4], u0[5]};
    d.c[1] = Float4{u0[2], u0[3], u0[6], u0[7]};
    d.c[2] = Float4{u1[0], u1[1], u1[4], u1[5]};
    d.c[3] = Float4{u1[2], u1[3], u1[6], u1[7]};
  }
  __attribute__((target("avx2,f16c"))) void encode(const Quad4& r, uint8_t* const lane[4],
                                                   const uint32_t cov[4]) const {
    // Lanes to texels: (r g b a) of lanes 0, 1 and of lanes 2, 3.
    const Float4 rg01 = __builtin_shufflevector(r.c[0], r.c[1], 0, 4, 1, 5);  // r0 g0 r1 g1
    const Float4 ba01 = __builtin_shufflevector(r.c[2], r.c[3], 0, 4, 1, 5);
    const Float4 rg23 = __builtin_shufflevector(r.c[0], r.c[1], 2, 6, 3, 7);
    const Float4 ba23 = __builtin_shufflevector(r.c[2], r.c[3], 2, 6, 3, 7);
    const Float8 t01 = {rg01[0], rg01[1], ba01[0], ba01[1], rg01[2], rg01[3], ba01[2], ba01[3]};
    const Float8 t23 = {rg23[0], rg23[1], ba23[0], ba23[1], rg23[2], rg23[3], ba23[2], ba23[3]};
    __m128i row[2] = {_mm256_cvtps_ph(__m256(t01), _MM_FROUND_TO_NEAREST_INT),
                      _mm256_cvtps_ph(__m256(t23), _MM_FROUND_TO_NEAREST_INT)};
    for (__m128i& v : row) {
      const __m128i exp = _mm_set1_epi16(0x7C00), man = _mm_set1_epi16(0x03FF);
      const __m128i nan = _mm_andnot_si128(_mm_cmpeq_epi16(_mm_and_si128(v, man), _mm_setzero_si128()),
                                           _mm_cmpeq_epi16(_mm_and_si128(v, exp), exp));
      v = _mm_or_si128(_mm_andnot_si128(nan, v), _mm_and_si128(nan, _mm_set1_epi16(0x7E00)));
    }
    for (int h = 0; h < 2; ++h) {
      if (cov[2 * h] && cov[2 * h + 1]) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(lane[2 * h]), row[h]);
        continue;
      }
      if (cov[2 * h]) _mm_storel_epi64(reinterpret_cast<__m128i*>(lane[2 * h]), row[h]);
      if (cov[2 * h + 1])
        _mm_storel_epi64(reinterpret_cast<__m128i*>(lane[2 * h + 1]), _mm_unpackhi_epi64(row[h], row[h]));
    }
  }
};

template <bool kBlend, bool kReadDst, int kShape = -1>
__attribute__((target("avx2,f16c"))) void colorHalf4QuadF16c(const DrawContext& ctx, uint32_t i, const FragmentQuad& q,
                                                             const uint32_t cov[4]) {
  half4Quad<kBlend, kReadDst, kShape>(ctx, i, q, cov, Half4CodecF16c{});
}
#endif

// The float16 quad writes of one kind: the F16C copy (kF16c) or the baseline one.
template <bool kF16c, bool kBlend, bool kReadDst, int kShape = -1>
constexpr auto half4QuadOf() -> decltype(&colorHalf4Quad<false, false>) {
#if defined(__x86_64__)
  if constexpr (kF16c) return colorHalf4QuadF16c<kBlend, kReadDst, kShape>;
#endif
  return colorHalf4Quad<kBlend, kReadDst, kShape>;
}

// half4Quad's writes for an attachment's blend and write mask (kF16c: where the quad writes take AVX2 and the CPU has
// F16C).
template <bool kF16c>
auto half4QuadFor(const BlendAttachment& ba, bool readDst) -> decltype(&colorHalf4Quad<false, false>) {
  if (ba.enable) {
    switch (blendShapeOf(ba)) {
      case 0: return half4QuadOf<kF16c, true, true, 0>();
      case 1: return half4QuadOf<kF16c, true, true, 1>();
      case 2: return half4QuadOf<kF16c, true, true, 2>();
      case 3: return half4QuadOf<kF16c, true, true, 3>();
      default: return half4QuadOf<kF16c, true, true>();
    }
  }
  return readDst ? half4QuadOf<kF16c, false, true>() : half4QuadOf<kF16c, false, false>();
}

// The 8-bit UNorm (kSrgb: sRGB) quad writes of one kind: kAvx2's copy.
template <bool kAvx2, bool kBgra, bool kBlend, bool kReadDst, int kShape = -1, bool kSrgb = false>
constexpr auto unorm8Quad() -> decltype(&colorUnorm8Quad<kBgra, false, false>) {
#if defined(__x86_64__)
  if constexpr (kAvx2) return colorUnorm8QuadAvx2<kBgra, kBlend, kReadDst, kShape, kSrgb>;
#endif
  return colorUnorm8Quad<kBgra, kBlend, kReadDst, kShape, kSrgb>;
}

template <bool kAvx2, bool kBgra, bool kSrgb>
auto unorm8QuadFor(const BlendAttachment& ba, bool readDst) -> decltype(&colorUnorm8Quad<kBgra, false, false>) {
  if (ba.enable) {
    switch (blendShapeOf(ba)) {
      case 0: return unorm8Quad<kAvx2, kBgra, true, true, 0, kSrgb>();
      case 1: return unorm8Quad<kAvx2, kBgra, true, true, 1, kSrgb>();
      case 2: return unorm8Quad<kAvx2, kBgra, true, true, 2, kSrgb>();
      case 3: return unorm8Quad<kAvx2, kBgra, true, true, 3, kSrgb>();
      default: return unorm8Quad<kAvx2, kBgra, true, true, -1, kSrgb>();
    }
  }
  return readDst ? unorm8Quad<kAvx2, kBgra, false, true, -1, kSrgb>()
                 : unorm8Quad<kAvx2, kBgra, false, false, -1, kSrgb>();
}

// unorm8QuadFor of the attachment's layout and the CPU's copy.
template <bool kAvx2>
auto unorm8QuadOf(const ColorFormat& fmt, const BlendAttachment& ba, bool readDst)
    -> decltype(&colorUnorm8Quad<false, false, false>) {
  if (fmt.srgb())
    return fmt.bgra() ? unorm8QuadFor<kAvx2, true, true>(ba, readDst) : unorm8QuadFor<kAvx2, false, true>(ba, readDst);
  return fmt.bgra() ? unorm8QuadFor<kAvx2, true, false>(ba, readDst) : unorm8QuadFor<kAvx2, false, false>(ba, readDst);
}

// Whether planBackEnd takes the AVX2 copy of the 8-bit UNorm quad writes (and rasterizeTile that of the tile loop):
// where the CPU has AVX2, unless VKRT_QUAD_ISA=baseline (which selects the quad sampler's baseline copy too);
// setQuadWritesAvx2 (the tests).
std::atomic<bool> gQuadWritesAvx2{exec::quadAvx2ByDefault()};

}  // namespace

void setQuadPaths(bool enabled) { quadPaths.store(enabled, std::memory_order_relaxed); }

bool encodeSrgb8Octets(const float* in, uint32_t* out, size_t n) {
#if defined(__x86_64__)
  if (!exec::hostHasAvx2()) return false;
  encodeSrgb8OctetsAvx2(in, out, n);
  return true;
#else
  (void)in, (void)out, (void)n;
  return false;
#endif
}

void encodeSrgb8Quads(const float* in, uint32_t* out, size_t n) {
  const abi::Srgb8Tables& t = abi::srgb8Tables();
  for (size_t i = 0; i + 4 <= n; i += 4) {
    Float4 x;
    std::memcpy(&x, in + i, 16);
    const UInt4 v = srgbEncode4(t, x);
    std::memcpy(out + i, &v, 16);
  }
}

bool setQuadWritesAvx2(bool enabled) {
  if (enabled && !exec::hostHasAvx2()) return false;
  gQuadWritesAvx2.store(enabled, std::memory_order_relaxed);
  return true;
}

bool quadWritesAvx2() { return gQuadWritesAvx2.load(std::memory_order_relaxed); }

void planBackEnd(DrawContext& ctx) {
  const Target& tg = *ctx.target;
  const State& st = *ctx.state;
  const bool quads = quadPaths.load(std::memory_order_relaxed) && ctx.samples == 1;
  BackEndPlan& plan = ctx.backEnd;
  plan.quadPaths = 0;
  // Depth/stencil: what depthStencilTests would run.
  const DepthStencilTarget& ds = tg.depthStencil;
  const bool hasDepth = ds.depthFormat != DepthFormat::None && ds.depth.base;
  const bool hasStencil = ds.stencilFormat != StencilFormat::None && ds.stencil.base;
  const bool bounds = st.depthBoundsTest && hasDepth, stencil = st.stencilTest && hasStencil;
  const bool depth = st.depthTest && hasDepth;
  if (!bounds && !stencil && !depth) {
    plan.depthStencil = noDepthStencil;
  } else if (quads && !bounds && !stencil && ds.depth.samples == 1) {
    switch (ds.depthFormat) {
      case DepthFormat::D16UNorm:
        plan.depthStencil = depthQuadFor<DepthFormat::D16UNorm>(st.depthCompare, st.depthWrite);
        break;
      case DepthFormat::X8D24UNorm:
        plan.depthStencil = depthQuadFor<DepthFormat::X8D24UNorm>(st.depthCompare, st.depthWrite);
        break;
      default: plan.depthStencil = depthQuadFor<DepthFormat::D32SFloat>(st.depthCompare, st.depthWrite); break;
    }
    plan.quadPaths |= 1;
  } else {
    plan.depthStencil = depthStencilLanes;
  }
  // Colour: attachments the shader writes, with a format that encodes and a write mask that keeps something.
  for (uint32_t i = 0; i < kMaxColorAttachments; ++i) plan.color[i] = nullptr;
  for (uint32_t i = 0; i < tg.colorCount; ++i) {
    const ColorFormat& fmt = tg.colorFormat[i];
    if (!tg.color[i].base || !(ctx.fragment->outputMask >> i & 1) || !fmt.encode) continue;
    if (fmt.rgba16Float && quads && tg.color[i].samples == 1 && !st.logicOpEnable) {
      const BlendAttachment& ba = st.blend[i];
      const uint32_t mask = ba.writeMask & fmt.componentMask;
      if (!mask) continue;
      const bool readDst = ba.enable || mask != 0xF;
      plan.color[i] =
          quadWritesAvx2() && exec::hostHasF16c() ? half4QuadFor<true>(ba, readDst) : half4QuadFor<false>(ba, readDst);
      plan.quadPaths |= 2u << i;
      continue;
    }
    uint32_t mask;
    const bool unorm8 = unorm8Path(ctx, i, &mask);
    if (!mask) continue;
    if (!unorm8) {
      plan.color[i] = colorLanes;
    } else if (quads && tg.color[i].samples == 1) {
      const bool blend = st.blend[i].enable, readDst = blend || mask != 0xF;
      const BlendAttachment& ba = st.blend[i];
      plan.color[i] = quadWritesAvx2() ? unorm8QuadOf<true>(fmt, ba, readDst) : unorm8QuadOf<false>(fmt, ba, readDst);
      plan.quadPaths |= 2u << i;
    } else {
      plan.color[i] = colorUnorm8Lanes;
    }
  }
}

}  // namespace vkrt::raster::detail

namespace vkrt::raster {

int blendShape(const BlendAttachment& b) { return detail::blendShapeOf(b); }

}  // namespace vkrt::raster
