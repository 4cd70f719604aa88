// The image functions compiled shaders call (abi/image_functions.hpp), on vkrt's image views, buffer views and
// samplers.
#include "runtime/image_functions.hpp"

#include "abi/shader_debug.hpp"
#include "abi/srgb8.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "exec/supervise.hpp"
#include "runtime/bc_texel.hpp"
#include "runtime/buffer.hpp"
#include "runtime/buffer_view.hpp"
#include "runtime/descriptor_set_layout.hpp"
#include "runtime/image.hpp"
#include "runtime/image_copy.hpp"
#include "runtime/image_view.hpp"
#include "runtime/lod_log2.hpp"
#include "runtime/quad_sampling.hpp"
#include "runtime/sampler.hpp"
#include "runtime/srgb.hpp"

namespace vkrt {

namespace {

using N = NumericType;

uint32_t fbits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}
float bitsf(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

float halfToFloat(uint32_t h) {
  uint32_t sign = (h >> 15) & 1, exp = (h >> 10) & 31, man = h & 1023;
  float v;
  if (exp == 0)
    v = std::ldexp(float(man), -24);
  else if (exp == 31)
    v = man ? NAN : INFINITY;
  else
    v = std::ldexp(float(man | 1024), int(exp) - 25);
  return sign ? -v : v;
}

// An unsigned small float (B10G11R11): 5-bit exponent, `mb` mantissa bits, no sign.
float smallFloatToFloat(uint32_t v, int mb) {
  uint32_t exp = v >> mb, man = v & ((1u << mb) - 1);
  if (exp == 0) return std::ldexp(float(man), -14 - mb);
  if (exp == 31) return man ? NAN : INFINITY;
  return std::ldexp(float(man | (1u << mb)), int(exp) - 15 - mb);
}

uint64_t readBits(const uint8_t* p, unsigned bytes) {
  // Fixed-size loads for the component sizes formats have: a memcpy of a variable size is a library call, which
  // was half of a blit's time.
  switch (bytes) {
    case 1: return p[0];
    case 2: {
      uint16_t v;
      std::memcpy(&v, p, 2);  // little-endian host
      return v;
    }
    case 4: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      uint64_t v = 0;
      std::memcpy(&v, p, bytes);
      return v;
    }
  }
}

void writeBits(uint8_t* p, uint64_t v, unsigned bytes) {
  switch (bytes) {  // fixed sizes, as in readBits
    case 1: p[0] = uint8_t(v); return;
    case 2: {
      const uint16_t w = uint16_t(v);
      std::memcpy(p, &w, 2);
      return;
    }
    case 4: {
      const uint32_t w = uint32_t(v);
      std::memcpy(p, &w, 4);
      return;
    }
    default: std::memcpy(p, &v, bytes); return;
  }
}

// 8-bit UNorm and sRGB components, the most sampled, by table: the values decodeComponent computes below (the sRGB
// one is abi/srgb8.hpp's, which the raster's quad writes read too).
struct Unorm8Tables {
  float unorm[256], srgb[256];
  Unorm8Tables() {
    const abi::Srgb8Tables& s = abi::srgb8Tables();
    for (uint32_t i = 0; i < 256; ++i) {
      unorm[i] = float(double(i) / 255.0);
      srgb[i] = s.decode[i];  // srgbToLinear(unorm[i])
    }
  }
};
const Unorm8Tables kUnorm8;

// Decodes one raw component value of `bits` bits.
uint32_t decodeComponent(N type, uint64_t raw, unsigned bits, bool alpha) {
  uint64_t maxU = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  if (bits == 8 && (type == N::UNorm || type == N::SRGB))
    return fbits(type == N::SRGB && !alpha ? kUnorm8.srgb[raw] : kUnorm8.unorm[raw]);
  switch (type) {
    case N::UNorm: return fbits(float(double(raw) / double(maxU)));
    case N::SRGB: {
      float f = float(double(raw) / double(maxU));
      return fbits(alpha ? f : srgbToLinear(f));
    }
    case N::SNorm: {
      int64_t s = int64_t(raw << (64 - bits)) >> (64 - bits);
      return fbits(std::max(-1.0f, float(double(s) / double((1ll << (bits - 1)) - 1))));
    }
    case N::UInt: return uint32_t(raw);
    case N::SInt: return uint32_t(int32_t(int64_t(raw << (64 - bits)) >> (64 - bits)));
    case N::SFloat: return bits == 16 ? fbits(halfToFloat(uint32_t(raw))) : uint32_t(raw);
    case N::UFloat: return fbits(smallFloatToFloat(uint32_t(raw), int(bits) - 5));
  }
  return 0;
}

uint64_t encodeComponent(N type, uint32_t word, unsigned bits, bool alpha) {
  uint64_t maxU = (1ull << bits) - 1;
  float f = bitsf(word);
  switch (type) {
    case N::UNorm:
    case N::SRGB: {
      // 8-bit sRGB: the nearest byte to the exact encoding, by table (abi/srgb8.hpp; NaN 0, clamped to [0, 1]).
      if (type == N::SRGB && !alpha && bits == 8) return abi::srgb8Tables().encode(f);
      if (type == N::SRGB && !alpha) f = linearToSrgb(f);
      f = std::isnan(f) ? 0.0f : std::clamp(f, 0.0f, 1.0f);
      // 8-bit UNorm, the attachments' and storage images' commonest: times 255 in float, rounded to nearest even
      // (adding and subtracting 2^23 leaves no fraction bits below 256; the current rounding mode, as CVTPS2DQ's):
      // one of the two integers nearest to f x 255, as "Conversion from Floating-Point to Normalized Fixed-Point"
      // allows, in one float multiplication where every inline copy (the raster's quad writes, image writes, the
      // compiler's) would otherwise widen to double; an 8-bit sRGB format's alpha, a UNorm component, alike. Other
      // widths times 2^b - 1 in double, exact.
      if (bits == 8) return uint64_t((f * 255.0f + 0x1p23f) - 0x1p23f);
      return uint64_t(std::nearbyint(double(f) * double(maxU)));
    }
    case N::SNorm: {
      f = std::isnan(f) ? 0.0f : std::clamp(f, -1.0f, 1.0f);
      int64_t s = int64_t(std::nearbyint(double(f) * double((1ll << (bits - 1)) - 1)));
      return uint64_t(s) & maxU;
    }
    case N::UInt:
    case N::SInt: return uint64_t(word) & maxU;  // the low bits (the spec leaves out-of-range values undefined)
    case N::SFloat: return bits == 16 ? floatToHalf(f) : word;
    case N::UFloat: return floatToUnsignedSmallFloat(f, int(bits) - 5);
  }
  return 0;
}

bool isIntFormat(const FormatInfo& f) { return f.type == N::UInt || f.type == N::SInt; }

// VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: component = mantissa * 2^(exponent - 15 - 9).
void decodeSharedExponent(uint32_t w, uint32_t c[4]) {
  const int e = int(w >> 27) - 24;
  for (unsigned i = 0; i < 3; ++i) c[i] = fbits(std::ldexp(float((w >> (9 * i)) & 511u), e));
}

// The inverse, as EXT_texture_shared_exponent defines it (N = 9 mantissa bits, bias B = 15, Emax = 31): components
// clamped to [0, (511/512) * 2^16] (NaN to 0), the exponent from the largest, raised by one when its mantissa
// rounds up to 512, each mantissa rounded to nearest. frexp gives floor(log2) exactly on every ISA.
uint32_t encodeSharedExponent(const uint32_t in[4]) {
  float c[3];
  float maxc = 0.0f;
  for (unsigned i = 0; i < 3; ++i) {
    const float f = bitsf(in[i]);
    c[i] = std::isnan(f) ? 0.0f : std::clamp(f, 0.0f, 65408.0f);
    maxc = std::max(maxc, c[i]);
  }
  int exp = 0;  // biased exponent
  if (maxc > 0.0f) {
    int e2;
    std::frexp(maxc, &e2);  // maxc = m * 2^e2, m in [0.5, 1): floor(log2(maxc)) = e2 - 1
    exp = std::max(-16, e2 - 1) + 16;
    if (std::floor(double(maxc) / std::ldexp(1.0, exp - 24) + 0.5) == 512.0) ++exp;
  }
  uint32_t w = uint32_t(exp) << 27;
  for (unsigned i = 0; i < 3; ++i) w |= uint32_t(std::floor(double(c[i]) / std::ldexp(1.0, exp - 24) + 0.5)) << (9 * i);
  return w;
}

}  // namespace

void decodeTexel(const FormatInfo& f, const uint8_t* texel, uint32_t out[4]) {
  texel += f.offset;  // the stencil byte of a combined depth/stencil texel
  if (!f.packed && f.components == 4 && f.texelSize == 4 && (f.type == N::UNorm || f.type == N::SRGB)) {
    // Four 8-bit normalized components (RGBA8, BGRA8 and their sRGB forms), the most common: by table, stored as
    // one 16-byte vector (callers read the words back in wider loads, which small stores would stall).
    using Words = float __attribute__((vector_size(16)));
    const float* rgb = f.type == N::SRGB ? kUnorm8.srgb : kUnorm8.unorm;
    const unsigned r = f.bgr ? 2 : 0;
    const Words v = {rgb[texel[r]], rgb[texel[1]], rgb[texel[2 - r]], kUnorm8.unorm[texel[3]]};
    std::memcpy(out, &v, 16);
    return;
  }
  uint32_t c[4] = {0, 0, 0, isIntFormat(f) ? 1u : fbits(1.0f)};
  if (f.packed) {
    // One 16- or 32-bit word, fields from bit 0 up (format.hpp).
    uint32_t w = uint32_t(readBits(texel, f.texelSize));
    if (f.format == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) {
      decodeSharedExponent(w, c);
    } else {
      unsigned shift = 0;
      for (unsigned i = 0; i < f.components; ++i) {
        uint32_t raw = (w >> shift) & ((1u << f.bits[i]) - 1);
        c[i] = decodeComponent(f.type, raw, f.bits[i], i == 3);
        shift += f.bits[i];
      }
      if (f.bgr) std::swap(c[0], c[2]);              // B,G,R(,A) from bit 0: R5G6B5, A1R5G5B5
      if (f.alphaLow) std::rotate(c, c + 1, c + 4);  // A,R,G,B from bit 0: B4G4R4A4
    }
  } else {
    unsigned at = 0;
    for (unsigned i = 0; i < f.components; ++i) {
      c[i] = decodeComponent(f.type, readBits(texel + at, f.bits[i] / 8), f.bits[i], i == 3);
      at += f.bits[i] / 8;
    }
    if (f.bgr) std::swap(c[0], c[2]);
  }
  std::memcpy(out, c, 16);
}

void encodeTexel(const FormatInfo& f, const uint32_t in[4], uint8_t* texel) {
  texel += f.offset;
  uint32_t c[4] = {in[0], in[1], in[2], in[3]};
  if (f.packed) {
    uint32_t w = 0;
    if (f.format == VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) {
      w = encodeSharedExponent(c);
    } else {
      if (f.bgr) std::swap(c[0], c[2]);
      if (f.alphaLow) std::rotate(c, c + 3, c + 4);  // R,G,B,A to A,R,G,B
      unsigned shift = 0;
      for (unsigned i = 0; i < f.components; ++i) {
        w |= uint32_t(encodeComponent(f.type, c[i], f.bits[i], i == 3)) << shift;
        shift += f.bits[i];
      }
    }
    writeBits(texel, w, f.texelSize);
    return;
  }
  if (f.bgr) std::swap(c[0], c[2]);
  unsigned at = 0;
  for (unsigned i = 0; i < f.components; ++i) {
    uint64_t v = encodeComponent(f.type, c[i], f.bits[i], i == 3);
    writeBits(texel + at, v, f.bits[i] / 8);
    at += f.bits[i] / 8;
  }
}

namespace {

// An image view resolved for addressing: the TexelView the sampling code reads, and the view (swizzle, type).
struct View : TexelView {
  const ImageView* view = nullptr;
};

bool resolveView(const abi::DescriptorRecord* rec, View* v) {
  if (!rec || !rec->object) return false;
  // A texel buffer's descriptor where the shader declares an image (a type mismatch the application should not
  // make) reads zeros rather than a buffer view taken for an image view.
  if (static_cast<const Object*>(rec->object)->objectType != VK_OBJECT_TYPE_IMAGE_VIEW) return false;
  v->view = recordObject<ImageView>(rec->object);
  v->image = v->view->image;
  // A depth/stencil view reads the aspect it selects (depth as R, stencil as an unsigned integer).
  v->format = aspectFormatInfo(v->view->format, v->view->range.aspectMask);
  if (!v->format || !v->image || !v->image->data()) return false;
  v->baseMip = v->view->range.baseMipLevel;
  v->levelCount = v->view->range.levelCount;
  v->baseLayer = v->view->range.baseArrayLayer;
  v->layerCount = v->view->range.layerCount;
  switch (v->view->viewType) {
    case VK_IMAGE_VIEW_TYPE_1D: v->dims = 1; break;
    case VK_IMAGE_VIEW_TYPE_1D_ARRAY:
      v->dims = 1;
      v->arrayed = true;
      break;
    case VK_IMAGE_VIEW_TYPE_2D: v->dims = 2; break;
    case VK_IMAGE_VIEW_TYPE_3D: v->dims = 3; break;
    default:
      v->dims = 2;
      v->arrayed = true;
      break;  // 2D array, cube, cube array: faces are layers
  }
  v->slicesAsLayers = v->image->type == VK_IMAGE_TYPE_3D && v->dims == 2;
  return true;
}

// The level's extent in the view's texels: an uncompressed view of a compressed image (created
// BLOCK_TEXEL_VIEW_COMPATIBLE) has one texel per block ("the view's extent in blocks": ceil(texels / 4)).
VkExtent3D levelExtent(const TexelView& v, uint32_t level) {
  VkExtent3D e = v.image->mips[v.baseMip + level].extent;
  if (v.slicesAsLayers) e.depth = 1;
  if (const uint32_t b = v.image->formatInfo->block; b > 1 && v.format->block == 1) {
    e.width = (e.width + b - 1) / b;
    e.height = (e.height + b - 1) / b;
  }
  return e;
}

// The texel's address, or nullptr when (x, y, z, layer) is outside mip `level` of the view; for a compressed view,
// the address of the block that holds the texel (Image::texel takes block coordinates: an uncompressed view of a
// compressed image addresses its blocks as texels).
uint8_t* texelAt(const TexelView& v, uint32_t level, int64_t x, int64_t y, int64_t z, int64_t layer) {
  if (level >= v.levelCount) return nullptr;
  VkExtent3D e = levelExtent(v, level);
  if (x < 0 || y < 0 || z < 0 || layer < 0 || x >= e.width || y >= e.height || z >= e.depth) return nullptr;
  if (v.format->block > 1) {
    x /= v.format->block;
    y /= v.format->block;
  }
  if (v.slicesAsLayers) {
    int64_t slice = int64_t(v.baseLayer) + layer;
    if (layer >= int64_t(v.layerCount) || slice >= v.image->mips[v.baseMip + level].extent.depth) return nullptr;
    return v.image->texel(v.baseMip + level, 0, uint32_t(x), uint32_t(y), uint32_t(slice));
  }
  if (layer >= int64_t(v.layerCount)) return nullptr;
  return v.image->texel(v.baseMip + level, v.baseLayer + uint32_t(layer), uint32_t(x), uint32_t(y), uint32_t(z));
}

// Splits view-order coordinates into (x, y, z, layer).
void splitCoord(const TexelView& v, const int64_t c[4], int64_t out[4]) {
  out[0] = c[0];
  out[1] = v.dims >= 2 ? c[1] : 0;
  out[2] = v.dims >= 3 ? c[2] : 0;
  out[3] = v.arrayed ? c[v.dims] : 0;
}

void readTexel(const TexelView& v, uint32_t level, const int64_t xyzl[4], uint32_t out[4]) {
  const uint8_t* t = texelAt(v, level, xyzl[0], xyzl[1], xyzl[2], xyzl[3]);
  if (!t) {
    std::memset(out, 0, 16);
    return;
  }
  // A compressed view: the texel of its block (every read, fetch, filter, gather and blit source comes here).
  if (v.format->block > 1) {
    decodeBcTexel(*v.format, t, uint32_t(xyzl[0] & 3), uint32_t(xyzl[1] & 3), out);
    return;
  }
  decodeTexel(*v.format, t, out);
}

void applySwizzle(const View& v, uint32_t c[4]) {
  const VkComponentMapping& m = v.view->components;
  if ((m.r == VK_COMPONENT_SWIZZLE_IDENTITY || m.r == VK_COMPONENT_SWIZZLE_R) &&
      (m.g == VK_COMPONENT_SWIZZLE_IDENTITY || m.g == VK_COMPONENT_SWIZZLE_G) &&
      (m.b == VK_COMPONENT_SWIZZLE_IDENTITY || m.b == VK_COMPONENT_SWIZZLE_B) &&
      (m.a == VK_COMPONENT_SWIZZLE_IDENTITY || m.a == VK_COMPONENT_SWIZZLE_A))
    return;  // the common identity mapping
  uint32_t one = isIntFormat(*v.format) ? 1u : fbits(1.0f);
  uint32_t src[4] = {c[0], c[1], c[2], c[3]};
  VkComponentSwizzle s[4] = {v.view->components.r, v.view->components.g, v.view->components.b, v.view->components.a};
  for (int i = 0; i < 4; ++i) {
    switch (s[i]) {
      case VK_COMPONENT_SWIZZLE_IDENTITY: c[i] = src[i]; break;
      case VK_COMPONENT_SWIZZLE_ZERO: c[i] = 0; break;
      case VK_COMPONENT_SWIZZLE_ONE: c[i] = one; break;
      case VK_COMPONENT_SWIZZLE_R: c[i] = src[0]; break;
      case VK_COMPONENT_SWIZZLE_G: c[i] = src[1]; break;
      case VK_COMPONENT_SWIZZLE_B: c[i] = src[2]; break;
      case VK_COMPONENT_SWIZZLE_A: c[i] = src[3]; break;
      default: break;
    }
  }
}

// Applies the address mode to integer texel coordinate i of a dimension with `size` texels; false: border.
bool wrap(VkSamplerAddressMode mode, int64_t i, int64_t size, int64_t* out) {
  // Inside the level every mode leaves the coordinate as it is (and the divisions below are slow).
  if (i >= 0 && i < size) {
    *out = i;
    return true;
  }
  switch (mode) {
    case VK_SAMPLER_ADDRESS_MODE_REPEAT: *out = ((i % size) + size) % size; return true;
    case VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT: {
      int64_t t = ((i % (2 * size)) + 2 * size) % (2 * size);
      *out = t < size ? t : 2 * size - 1 - t;
      return true;
    }
    case VK_SAMPLER_ADDRESS_MODE_MIRROR_CLAMP_TO_EDGE: *out = std::min(i >= 0 ? i : -(1 + i), size - 1); return true;
    case VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER: *out = i; return i >= 0 && i < size;
    default: *out = std::clamp<int64_t>(i, 0, size - 1); return true;  // CLAMP_TO_EDGE
  }
}

// "Border Replacement" replaces only the components the format (or the depth/stencil aspect) has; the others then
// take the values of "Component Substitution" as a texel read would give them: 0 for G and B, 1 for A (B10G11R11
// with a TRANSPARENT_BLACK border reads alpha 1; a stencil aspect with OPAQUE_WHITE reads (1, 0, 0, 1)).
void substituteMissingComponents(const FormatInfo& f, uint32_t c[4]) {
  for (unsigned i = f.components; i < 3; ++i) c[i] = 0;
  if (f.components < 4) c[3] = isIntFormat(f) ? 1u : fbits(1.0f);
}

void borderColor(const TexelView& v, VkBorderColor bc, uint32_t out[4]) {
  bool opaque = bc == VK_BORDER_COLOR_FLOAT_OPAQUE_BLACK || bc == VK_BORDER_COLOR_INT_OPAQUE_BLACK;
  bool white = bc == VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE || bc == VK_BORDER_COLOR_INT_OPAQUE_WHITE;
  uint32_t one = isIntFormat(*v.format) ? 1u : fbits(1.0f);
  out[0] = out[1] = out[2] = white ? one : 0;
  out[3] = (opaque || white) ? one : 0;
  substituteMissingComponents(*v.format, out);
}

// The texel at integer (i, j, k) of `level` after the address modes, as four words.
void addressedTexel(const TexelView& v, const VkSamplerCreateInfo& s, uint32_t level, int64_t i, int64_t j, int64_t k,
                    int64_t layer, uint32_t out[4]) {
  VkExtent3D e = levelExtent(v, level);
  int64_t c[3];
  bool inside = wrap(s.addressModeU, i, e.width, &c[0]);
  if (v.dims >= 2)
    inside = wrap(s.addressModeV, j, e.height, &c[1]) && inside;
  else
    c[1] = 0;
  if (v.dims >= 3)
    inside = wrap(s.addressModeW, k, e.depth, &c[2]) && inside;
  else
    c[2] = 0;
  if (!inside) {
    borderColor(v, s.borderColor, out);
    return;
  }
  int64_t xyzl[4] = {c[0], c[1], c[2], layer};
  readTexel(v, level, xyzl, out);
}

// The depth comparison of an OpImage*Dref* instruction ("Depth Compare Operation"): the reference value (already
// clamped to [0, 1] for UNORM depth) and the operator, applied to each texel before filtering.
struct DepthCompare {
  float ref = 0;
  VkCompareOp op = VK_COMPARE_OP_NEVER;
};

// "reference op test" (VkCompareOp), with the texel's depth as the test value; 1.0 or 0.0.
float compareDepth(const DepthCompare& c, float test) {
  bool pass = false;
  switch (c.op) {
    case VK_COMPARE_OP_LESS: pass = c.ref < test; break;
    case VK_COMPARE_OP_EQUAL: pass = c.ref == test; break;
    case VK_COMPARE_OP_LESS_OR_EQUAL: pass = c.ref <= test; break;
    case VK_COMPARE_OP_GREATER: pass = c.ref > test; break;
    case VK_COMPARE_OP_NOT_EQUAL: pass = c.ref != test; break;
    case VK_COMPARE_OP_GREATER_OR_EQUAL: pass = c.ref >= test; break;
    case VK_COMPARE_OP_ALWAYS: pass = true; break;
    default: break;  // NEVER
  }
  return pass ? 1.0f : 0.0f;
}

// The texel (after the address modes and border replacement) with its depth, R, replaced by the comparison's
// result when there is one.
void comparedTexel(const TexelView& v, const VkSamplerCreateInfo& s, uint32_t level, int64_t i, int64_t j, int64_t k,
                   int64_t layer, const DepthCompare* cmp, uint32_t out[4]) {
  addressedTexel(v, s, level, i, j, k, layer, out);
  if (cmp) out[0] = fbits(compareDepth(*cmp, bitsf(out[0])));
}

// Filters mip `level` at view-order coordinates (normalized unless the sampler says otherwise); `offset` (null: none)
// moves the texels the filter reads by whole texels (the ConstOffset operand, "Texel Coordinate Systems"); with
// `cmp`, each texel's depth is compared before the filter averages the results (percentage-closer filtering).
void filterLevel(const TexelView& v, const VkSamplerCreateInfo& s, VkFilter filter, uint32_t level, const float* coord,
                 int64_t layer, const int32_t* offset, const DepthCompare* cmp, float out[4]) {
  VkExtent3D e = levelExtent(v, level);
  double size[3] = {double(e.width), double(e.height), double(e.depth)};
  double u[3] = {0, 0, 0};
  for (int d = 0; d < v.dims; ++d) u[d] = s.unnormalizedCoordinates ? double(coord[d]) : double(coord[d]) * size[d];
  bool isInt = isIntFormat(*v.format);
  if (filter == VK_FILTER_NEAREST || isInt) {
    int64_t i[3];
    for (int d = 0; d < 3; ++d) i[d] = int64_t(std::floor(u[d])) + (offset && d < v.dims ? offset[d] : 0);
    uint32_t t[4];
    comparedTexel(v, s, level, i[0], i[1], i[2], layer, cmp, t);
    std::memcpy(out, t, 16);
    return;
  }
  int64_t i0[3] = {0, 0, 0};
  double w[3] = {0, 0, 0};
  for (int d = 0; d < v.dims; ++d) {
    double f = u[d] - 0.5;
    i0[d] = int64_t(std::floor(f)) + (offset ? offset[d] : 0);
    w[d] = f - std::floor(f);
  }
  // The texels first, then their weighted sum (in the same order): the sum stays in registers instead of being
  // kept in memory across each texel's call.
  double weight[8];
  alignas(16) uint32_t t[8][4];
  int n = 0;
  int nk = v.dims >= 3 ? 2 : 1, nj = v.dims >= 2 ? 2 : 1;
  for (int dk = 0; dk < nk; ++dk)
    for (int dj = 0; dj < nj; ++dj)
      for (int di = 0; di < 2; ++di, ++n) {
        weight[n] = (di ? w[0] : 1 - w[0]) * (v.dims >= 2 ? (dj ? w[1] : 1 - w[1]) : 1.0) *
                    (v.dims >= 3 ? (dk ? w[2] : 1 - w[2]) : 1.0);
        comparedTexel(v, s, level, i0[0] + di, i0[1] + dj, i0[2] + dk, layer, cmp, t[n]);
      }
  double acc[4] = {0, 0, 0, 0};
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 4; ++c) acc[c] += weight[k] * double(bitsf(t[k][c]));
  for (int c = 0; c < 4; ++c) out[c] = float(acc[c]);
}

// The fast path of the most common sampling: a 2D (array) view of an 8-bit RGBA / BGRA UNorm or sRGB image, NEAREST
// or LINEAR filters, REPEAT or CLAMP_TO_EDGE in u and v, normalized coordinates, no depth comparison, no offset,
// identity or any swizzle (applied after, as on the generic path). The texel indices come from exact double
// arithmetic as filterLevel's, so the same texels are read; the LINEAR weights are quantized to 2^-8 (fixedCoord);
// the texels are decoded four components at once and weighed in float (UNorm: in byte units, scaled by 1/255 once).
// The difference to the generic path: less than 2^-8 per axis of the texels' difference, plus float rounding (a few
// ulp of 1.0). No FMA: the runtime is built for baseline x86-64, so the same on every CPU.
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int32_t __attribute__((vector_size(16)));

// fastSampling's two halves: the view's (also QuadView::fast) and the sampler's (also QuadSampler::fast, with
// anisotropyEnable off).
bool fastSamplingView(const View& v) {
  const FormatInfo& f = *v.format;
  return (v.view->viewType == VK_IMAGE_VIEW_TYPE_2D || v.view->viewType == VK_IMAGE_VIEW_TYPE_2D_ARRAY) &&
         !v.slicesAsLayers && v.image->samples == 1 && v.image->pixelSize == 4 && !f.packed && f.components == 4 &&
         f.texelSize == 4 && f.offset == 0 && (f.type == N::UNorm || f.type == N::SRGB) && f.block == 1;
}
bool fastSamplingSampler(const VkSamplerCreateInfo& s) {
  auto filterOk = [](VkFilter m) { return m == VK_FILTER_NEAREST || m == VK_FILTER_LINEAR; };
  auto addressOk = [](VkSamplerAddressMode m) {
    return m == VK_SAMPLER_ADDRESS_MODE_REPEAT || m == VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  };
  return !s.unnormalizedCoordinates && !s.compareEnable && filterOk(s.magFilter) && filterOk(s.minFilter) &&
         addressOk(s.addressModeU) && addressOk(s.addressModeV);
}
bool fastSampling(const View& v, const VkSamplerCreateInfo& s) { return fastSamplingView(v) && fastSamplingSampler(s); }

bool identityMapping(const VkComponentMapping& m) {
  auto same = [](VkComponentSwizzle c, VkComponentSwizzle own) {
    return c == VK_COMPONENT_SWIZZLE_IDENTITY || c == own;
  };
  return same(m.r, VK_COMPONENT_SWIZZLE_R) && same(m.g, VK_COMPONENT_SWIZZLE_G) && same(m.b, VK_COMPONENT_SWIZZLE_B) &&
         same(m.a, VK_COMPONENT_SWIZZLE_A);
}

// What fastFilterLevel reads of the view and the sampler, resolved once per call (once per quad for
// vkrt_image_sample_grad_quad) rather than per level and lane.
struct FastView {
  const uint8_t* data = nullptr;    // the image's first byte
  const MipLayout* mips = nullptr;  // the view's base level first
  uint64_t baseLayer = 0;
  bool srgb = false, bgr = false, repeatU = false, repeatV = false;
  bool identity = false;  // the view's component mapping changes nothing (applySwizzle returns at once)
};

// fastSampling's decision with its FastView; null where the generic path samples.
const FastView* fastView(const View& v, const VkSamplerCreateInfo& s, FastView* out) {
  if (!fastSampling(v, s)) return nullptr;
  out->data = v.image->data();
  out->mips = &v.image->mips[v.baseMip];
  out->baseLayer = v.baseLayer;
  out->srgb = v.format->type == N::SRGB;
  out->bgr = v.format->bgr;
  out->repeatU = s.addressModeU == VK_SAMPLER_ADDRESS_MODE_REPEAT;
  out->repeatV = s.addressModeV == VK_SAMPLER_ADDRESS_MODE_REPEAT;
  out->identity = identityMapping(v.view->components);
  return out;
}

// The fast path's texel addressing, in fixed point: a texel coordinate (minus 0.5 for LINEAR) plus 2 texels, in units
// of 2^-kSubTexelBits texel (quad_sampling.hpp), truncated. Its integer part is the first texel (floor(u - 0.5) + 2,
// as filterLevel's floor in double: the fixed-point value comes from exact double arithmetic), its fraction the
// LINEAR weight, quantized to 2^-8: the 2^-subTexelPrecisionBits (physical_device.cpp) "Texel Filtering" allows.
// (8-bit weights make every lerp of 8-bit UNorm texels exact in float, fastFilterLevel, so that the quad sampler's
// integer filter, quad_sampling_kernels.inc, gives the same bits.)
constexpr double kSubTexel = double(1 << kSubTexelBits);

// floor(x) as an integer for |x| < 2^63 (std::floor is a library call on the baseline x86-64 target: no SSE4.1).
inline int64_t floorInt(double x) {
  const int64_t i = int64_t(x);
  return i - int64_t(double(i) > x);
}

// A lane's coordinate prepared once for every level: REPEAT takes its fraction (in [0, 1], exact in double except a
// tiny negative coordinate's, which rounds to 1: texel size - 1 as the modulo gives), so that no level needs a
// division; CLAMP_TO_EDGE the coordinate as it is.
inline double fastCoord(bool repeat, float c) {
  const double d = c;
  return repeat ? d - double(floorInt(d)) : d;
}

// The fixed-point coordinate of fastCoord's `c` in a level of `size` texels, less `half` (0.5: LINEAR; 0: NEAREST).
// CLAMP_TO_EDGE clamps the texel coordinate to [-1, size + 1] first, which reads the same (edge) texels and keeps the
// value positive; REPEAT's is in [0, size] already. Exact where it decides a texel: c times size (at most 2^14
// texels) and the constants fit a double, except for REPEAT's fraction of a coordinate in (-2^-15, 0) (bits below
// 2^-53 rounded), whose texel coordinate is in (size - 0.5, size]: the rounding never changes its texels.
inline int64_t fixedCoord(bool repeat, double c, int64_t size, double half) {
  double u = c * double(size);
  if (!repeat) u = u < -1.0 ? -1.0 : u > double(size + 1) ? double(size + 1) : u;
  return int64_t((u + (2.0 - half)) * kSubTexel);
}

// Index i (at least -1, at most size when repeating) after the address mode.
inline int64_t wrapFast(bool repeat, int64_t i, int64_t size) {
  if (repeat) return i < 0 ? size - 1 : i >= size ? 0 : i;
  return i < 0 ? 0 : i >= size ? size - 1 : i;
}

inline uint32_t load32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// Two UNorm texels (32 bits each) as byte units (0..255) in floats: SSE2's unpacks (the baseline x86-64 target has no
// byte-to-word widening; GCC's generic vector shuffles come out as word extracts), converted four at a time. BGRA:
// red and blue swapped.
inline void unormPair(uint32_t p, uint32_t q, bool bgr, Float4* a, Float4* b) {
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  const __m128i bytes = _mm_unpacklo_epi32(_mm_cvtsi32_si128(int(p)), _mm_cvtsi32_si128(int(q)));
  const __m128i words = _mm_unpacklo_epi8(bytes, zero);
  Float4 fa = Float4(_mm_cvtepi32_ps(_mm_unpacklo_epi16(words, zero)));
  Float4 fb = Float4(_mm_cvtepi32_ps(_mm_unpackhi_epi16(words, zero)));
#else
  using Bytes4 = uint8_t __attribute__((vector_size(4)));
  Bytes4 bp, bq;
  std::memcpy(&bp, &p, 4);
  std::memcpy(&bq, &q, 4);
  Float4 fa = __builtin_convertvector(bp, Float4), fb = __builtin_convertvector(bq, Float4);
#endif
  if (bgr) {
    fa = __builtin_shufflevector(fa, fa, 2, 1, 0, 3);
    fb = __builtin_shufflevector(fb, fb, 2, 1, 0, 3);
  }
  *a = fa;
  *b = fb;
}

// One sRGB texel's four components, linear (0..1), by the decode tables.
inline Float4 srgbTexel(const uint8_t* p, bool bgr) {
  const unsigned r = bgr ? 2 : 0;
  return Float4{kUnorm8.srgb[p[r]], kUnorm8.srgb[p[1]], kUnorm8.srgb[p[2 - r]], kUnorm8.unorm[p[3]]};
}

// Filters level `level` at fastCoord's (cu, cv) (fastSampling's case): UNorm in byte units (0..255), sRGB in 0..1.
// LINEAR weighs with the fixed-point fractions: every lerp is exact in float for UNorm (8-bit texels, 8-bit weights:
// the rows' sums have 16 significant bits, the column's 24), which the quad sampler's integer filter relies on.
__attribute__((always_inline)) inline Float4 fastFilterLevel(const FastView& v, VkFilter filter, uint32_t level,
                                                             double cu, double cv, int64_t layer) {
  const MipLayout& m = v.mips[level];
  const int64_t w = m.extent.width, h = m.extent.height;
  const uint8_t* base = v.data + m.offset + (v.baseLayer + uint64_t(layer)) * m.arrayPitch;
  const size_t pitch = m.rowPitch, px = 4;  // fastSampling's pixelSize
  if (filter == VK_FILTER_NEAREST) {
    // REPEAT: u <= size, = size for the fraction rounded to 1 (its texel is size - 1).
    const int64_t i = wrapFast(v.repeatU, std::min((fixedCoord(v.repeatU, cu, w, 0.0) >> kSubTexelBits) - 2, w - 1), w);
    const int64_t j = wrapFast(v.repeatV, std::min((fixedCoord(v.repeatV, cv, h, 0.0) >> kSubTexelBits) - 2, h - 1), h);
    const uint8_t* p = base + size_t(j) * pitch + size_t(i) * px;
    if (v.srgb) return srgbTexel(p, v.bgr);
    Float4 r, unused;
    unormPair(load32(p), 0, v.bgr, &r, &unused);
    return r;
  }
  const int64_t x = fixedCoord(v.repeatU, cu, w, 0.5), y = fixedCoord(v.repeatV, cv, h, 0.5);
  const int64_t fu = (x >> kSubTexelBits) - 2, fv = (y >> kSubTexelBits) - 2;
  // REPEAT: fu is in [-1, size - 1], so only the first index wraps below and the second above.
  const int64_t i0 = v.repeatU ? (fu < 0 ? w - 1 : fu) : wrapFast(false, fu, w);
  const int64_t i1 = v.repeatU ? (fu + 1 >= w ? 0 : fu + 1) : wrapFast(false, fu + 1, w);
  const int64_t j0 = v.repeatV ? (fv < 0 ? h - 1 : fv) : wrapFast(false, fv, h);
  const int64_t j1 = v.repeatV ? (fv + 1 >= h ? 0 : fv + 1) : wrapFast(false, fv + 1, h);
  constexpr float kInv = float(1.0 / kSubTexel);
  const float a = float(int32_t(x & ((1 << kSubTexelBits) - 1))) * kInv;
  const float b = float(int32_t(y & ((1 << kSubTexelBits) - 1))) * kInv;
  const uint8_t* row0 = base + size_t(j0) * pitch;
  const uint8_t* row1 = base + size_t(j1) * pitch;
  Float4 t00, t10, t01, t11;
  if (v.srgb) {
    t00 = srgbTexel(row0 + size_t(i0) * px, v.bgr);
    t10 = srgbTexel(row0 + size_t(i1) * px, v.bgr);
    t01 = srgbTexel(row1 + size_t(i0) * px, v.bgr);
    t11 = srgbTexel(row1 + size_t(i1) * px, v.bgr);
  } else {
    unormPair(load32(row0 + size_t(i0) * px), load32(row0 + size_t(i1) * px), v.bgr, &t00, &t10);
    unormPair(load32(row1 + size_t(i0) * px), load32(row1 + size_t(i1) * px), v.bgr, &t01, &t11);
  }
  const Float4 top = t00 + a * (t10 - t00), bottom = t01 + a * (t11 - t01);
  return top + b * (bottom - top);
}

// fastSampling's case at level of detail d (clamped to [0, maxLevel]), with the generic path's level selection;
// false for a coordinate of magnitude 2^24 or more, or NaN (the generic path then decides).
__attribute__((always_inline)) inline bool fastSample(const FastView& v, VkFilter filter, VkSamplerMipmapMode mipmap,
                                                      float d, uint32_t maxLevel, const float* coord, int64_t layer,
                                                      float out[4]) {
  if (!(std::fabs(coord[0]) < 0x1p24f && std::fabs(coord[1]) < 0x1p24f)) return false;
  const double cu = fastCoord(v.repeatU, coord[0]), cv = fastCoord(v.repeatV, coord[1]);
  // d is in [0, maxLevel]: floor and ceil by truncation, not library calls.
  Float4 r;
  const uint32_t lo = uint32_t(d);
  if (mipmap == VK_SAMPLER_MIPMAP_MODE_NEAREST || d == float(lo)) {
    // Level ceil(d + 0.5) - 1: d rounded with halves going down.
    const float x = d + 0.5f;
    const uint32_t ceil = uint32_t(x) + (float(uint32_t(x)) < x ? 1 : 0);  // at least 1
    r = fastFilterLevel(v, filter, std::min(ceil - 1, maxLevel), cu, cv, layer);
  } else {
    const uint32_t hi = std::min(lo + 1, maxLevel);
    const float t = d - float(lo);
    r = fastFilterLevel(v, filter, lo, cu, cv, layer) * (1 - t) + fastFilterLevel(v, filter, hi, cu, cv, layer) * t;
  }
  if (!v.srgb) r *= 1.0f / 255.0f;  // sRGB texels came from the tables, already in 0..1
  std::memcpy(out, &r, 16);
  return true;
}

// A texel buffer's view resolved: its first texel, texel count and format.
struct TexelBuffer {
  uint8_t* data = nullptr;
  int64_t texels = 0;
  const FormatInfo* format = nullptr;
};

bool resolveTexelBuffer(const abi::DescriptorRecord* rec, TexelBuffer* t) {
  if (!rec || !rec->object) return false;
  // An image's descriptor where the shader declares a texel buffer reads zeros (see resolveView).
  if (static_cast<const Object*>(rec->object)->objectType != VK_OBJECT_TYPE_BUFFER_VIEW) return false;
  const BufferView* view = recordObject<BufferView>(rec->object);
  uint8_t* base = view->buffer ? view->buffer->data() : nullptr;
  if (!view->formatInfo || !base) return false;
  t->format = view->formatInfo;
  t->data = base + view->offset;
  t->texels = int64_t(view->range / view->formatInfo->texelSize);  // the range is a whole number of texels
  return true;
}

// Texel `index` of the view, or nullptr outside it.
uint8_t* texelAt(const TexelBuffer& t, int64_t index) {
  if (index < 0 || index >= t.texels) return nullptr;
  return t.data + uint64_t(index) * t.format->texelSize;
}

}  // namespace

void filterTexels(const TexelView& v, const VkSamplerCreateInfo& s, VkFilter filter, uint32_t level, const float* coord,
                  int64_t layer, uint32_t out[4]) {
  float f[4];
  filterLevel(v, s, filter, level, coord, layer, nullptr, nullptr, f);
  std::memcpy(out, f, 16);
}

QuadView describeQuadView(const ImageView& view) {
  QuadView q;
  abi::DescriptorRecord rec{};
  rec.object = static_cast<const Object*>(&view);
  View v;
  if (!resolveView(&rec, &v) || !fastSamplingView(v) || v.levelCount > kQuadMaxLevels) return q;
  q.srgb = v.format->type == N::SRGB;
  q.bgr = v.format->bgr;
  q.identity = identityMapping(view.components);
  q.arrayed = v.arrayed;
  q.levelCount = v.levelCount;
  q.layerCount = v.layerCount;
  const VkExtent3D e = levelExtent(v, 0);
  q.size[0] = float(e.width);
  q.size[1] = float(e.height);
  q.srgbTable = kUnorm8.srgb;
  q.unormTable = kUnorm8.unorm;
  for (uint32_t l = 0; l < v.levelCount; ++l) {
    const MipLayout& m = v.image->mips[v.baseMip + l];
    q.levels[l].layer0 = v.image->data() + m.offset + uint64_t(v.baseLayer) * m.arrayPitch;
    q.levels[l].arrayPitch = m.arrayPitch;
    q.levels[l].rowPitch = m.rowPitch;
    q.levels[l].width = int32_t(m.extent.width);
    q.levels[l].height = int32_t(m.extent.height);
  }
  q.offsets32 = true;
  for (uint32_t l = 0; l < v.levelCount; ++l)
    q.offsets32 = q.offsets32 && q.levels[l].rowPitch * uint64_t(q.levels[l].height) + 8 < (uint64_t(1) << 31);
  q.fast = true;
  return q;
}

StoreView describeStoreView(const ImageView& view) {
  StoreView s;
  abi::DescriptorRecord rec{};
  rec.object = static_cast<const Object*>(&view);
  View v;
  if (!resolveView(&rec, &v) || view.viewType != VK_IMAGE_VIEW_TYPE_2D || v.image->type != VK_IMAGE_TYPE_2D ||
      v.image->samples != 1 || v.levelCount == 0)
    return s;
  const FormatInfo& f = *v.format;
  if (f.packed || f.block != 1 || f.offset != 0) return s;
  bool all8 = true, all32 = true;
  for (unsigned i = 0; i < f.components; ++i) all8 = all8 && f.bits[i] == 8, all32 = all32 && f.bits[i] == 32;
  if (f.type == N::UNorm && f.components == 4 && all8) {
    s.kind = f.bgr ? StoreView::Kind::Unorm8Bgra : StoreView::Kind::Unorm8;
  } else if ((f.type == N::SFloat || f.type == N::UInt || f.type == N::SInt) && all32) {
    s.kind = StoreView::Kind::Words;
    s.words = f.components;
    s.integer = f.type != N::SFloat;
  } else {
    return s;
  }
  const VkExtent3D e = levelExtent(v, 0);
  s.format = &f;
  abi::ImageTexels& t = s.texels;
  t.texelBytes = f.texelSize;
  t.width = e.width;
  t.height = e.height;
  t.rowPitch = v.image->mips[v.baseMip].rowPitch;
  t.base = v.image->texel(v.baseMip, v.baseLayer, 0, 0, 0);
  t.kind = s.kind == StoreView::Kind::Words        ? s.words | (s.integer ? abi::kTexelsInteger : 0)
           : s.kind == StoreView::Kind::Unorm8Bgra ? abi::kTexelsUnorm8 | abi::kTexelsBgra
                                                   : abi::kTexelsUnorm8;
  return s;
}

QuadSampler describeQuadSampler(const VkSamplerCreateInfo& s) {
  QuadSampler q;
  if (!fastSamplingSampler(s) || s.anisotropyEnable) return q;
  q.repeatU = s.addressModeU == VK_SAMPLER_ADDRESS_MODE_REPEAT;
  q.repeatV = s.addressModeV == VK_SAMPLER_ADDRESS_MODE_REPEAT;
  q.magLinear = s.magFilter == VK_FILTER_LINEAR;
  q.minLinear = s.minFilter == VK_FILTER_LINEAR;
  q.mipLinear = s.mipmapMode == VK_SAMPLER_MIPMAP_MODE_LINEAR;
  q.mipLodBias = s.mipLodBias;
  q.minLod = s.minLod;
  q.maxLod = std::max(s.minLod, s.maxLod);
  q.fast = true;
  return q;
}

}  // namespace vkrt

using namespace vkrt;

extern "C" {

// The storage image fast path (StoreView): the texel at (x, y) of a view whose record is not None, or null outside
// it (a write does nothing, a read gives zeros, as texelAt's null).
static uint8_t* storeTexel(const StoreView& s, const int32_t coord[4]) {
  const uint32_t x = uint32_t(coord[0]), y = uint32_t(coord[1]);  // (negative ones wrap past the extent)
  const abi::ImageTexels& t = s.texels;
  if (x >= t.width || y >= t.height) return nullptr;
  return t.base + y * t.rowPitch + uint64_t(x) * t.texelBytes;
}

// The view's StoreView where the record holds an image view that has one, else null.
static const StoreView* storeView(const abi::DescriptorRecord* img) {
  if (!img || !img->object || static_cast<const Object*>(img->object)->objectType != VK_OBJECT_TYPE_IMAGE_VIEW)
    return nullptr;
  const StoreView& s = recordObject<ImageView>(img->object)->store;
  return s.kind != StoreView::Kind::None ? &s : nullptr;
}

void vkrt_image_read(const abi::DescriptorRecord* img, const int32_t coord[4], uint32_t out[4]) {
  if (const StoreView* s = storeView(img)) {
    const uint8_t* t = storeTexel(*s, coord);
    if (!t) {
      std::memset(out, 0, 16);
    } else if (s->kind == StoreView::Kind::Words) {
      // decodeTexel's: the format's words, then 0 and, for alpha, 1 (1.0 in a float format).
      uint32_t c[4] = {0, 0, 0, s->integer ? 1u : fbits(1.0f)};
      std::memcpy(c, t, size_t(s->words) * 4);
      std::memcpy(out, c, 16);
    } else {
      decodeTexel(*s->format, t, out);  // (its first case: the 8-bit UNorm table)
    }
    return;
  }
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v)) return;
  int64_t c[4] = {coord[0], coord[1], coord[2], coord[3]}, xyzl[4];
  splitCoord(v, c, xyzl);
  readTexel(v, 0, xyzl, out);
}

void vkrt_image_read_subpass(const abi::DescriptorRecord* img, int32_t x, int32_t y, int32_t layer, int32_t sample,
                             uint32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || sample < 0 || uint32_t(sample) >= v.image->samples || v.format->block > 1) return;
  const uint8_t* t = texelAt(v, 0, x, y, 0, layer);
  // Samples of a pixel are consecutive texels (Image::texel's pixelSize covers them all).
  if (t) decodeTexel(*v.format, t + size_t(sample) * v.image->formatInfo->texelSize, out);
}

void vkrt_image_write(const abi::DescriptorRecord* img, const int32_t coord[4], const uint32_t in[4]) {
  if (const StoreView* s = storeView(img)) {
    uint8_t* t = storeTexel(*s, coord);
    if (!t) return;
    if (s->kind == StoreView::Kind::Words) {
      std::memcpy(t, in, size_t(s->words) * 4);  // encodeComponent keeps 32-bit words as they are
      return;
    }
#if defined(__SSE2__)
    // encodeComponent's 8-bit UNorm: NaN to 0, clamped to [0, 1], times 255 in float, rounded in the current
    // rounding mode (CVTPS2DQ's).
    uint8_t b[4];
    // maxps gives its second operand, 0, for a NaN (and +0 for -0, which encodes alike), then minps clamps to 1.
    const __m128 f =
        _mm_min_ps(_mm_max_ps(_mm_loadu_ps(reinterpret_cast<const float*>(in)), _mm_setzero_ps()), _mm_set1_ps(1.0f));
    const __m128i words = _mm_cvtps_epi32(_mm_mul_ps(f, _mm_set1_ps(255.0f)));  // 0..255 each
    const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(words, words), _mm_setzero_si128());
    const uint32_t packed = uint32_t(_mm_cvtsi128_si32(bytes));
    std::memcpy(b, &packed, 4);
    if (s->kind == StoreView::Kind::Unorm8Bgra) std::swap(b[0], b[2]);
    std::memcpy(t, b, 4);
#else
    encodeTexel(*s->format, in, t);
#endif
    return;
  }
  View v;
  // Compressed views are never storage views (no STORAGE_IMAGE feature): nothing encodes a block.
  if (!resolveView(img, &v) || v.format->block > 1) return;
  int64_t c[4] = {coord[0], coord[1], coord[2], coord[3]}, xyzl[4];
  splitCoord(v, c, xyzl);
  uint8_t* t = texelAt(v, 0, xyzl[0], xyzl[1], xyzl[2], xyzl[3]);
  if (t) encodeTexel(*v.format, in, t);
}

void* vkrt_image_texel(const abi::DescriptorRecord* img, const int32_t coord[4]) {
  View v;
  // atomics: 32-bit formats only (never a compressed one)
  if (!resolveView(img, &v) || v.format->texelSize != 4 || v.format->block > 1) return nullptr;
  int64_t c[4] = {coord[0], coord[1], coord[2], coord[3]}, xyzl[4];
  splitCoord(v, c, xyzl);
  return texelAt(v, 0, xyzl[0], xyzl[1], xyzl[2], xyzl[3]);
}

void vkrt_image_fetch(const abi::DescriptorRecord* img, const int32_t coord[4], int32_t lod, uint32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || lod < 0) return;
  int64_t c[4] = {coord[0], coord[1], coord[2], coord[3]}, xyzl[4];
  splitCoord(v, c, xyzl);
  if (!texelAt(v, uint32_t(lod), xyzl[0], xyzl[1], xyzl[2], xyzl[3])) return;
  readTexel(v, uint32_t(lod), xyzl, out);
  applySwizzle(v, out);
}

// The layer a sampling instruction's array coordinate selects ("Image Level(s) Selection" rounds it, then clamps
// it to the view's layers).
static int64_t arrayLayer(const View& v, const float coord[4]) {
  if (!v.arrayed) return 0;
  float l = std::nearbyint(coord[v.dims]);
  return int64_t(std::clamp(l, 0.0f, float(v.layerCount - 1)));
}

// The depth comparison an OpImage*Dref* instruction makes with sampler `s` ("Depth Compare Operation"): the
// sampler's compareOp; Dref clamped to [0, 1] when the view's depth is UNORM (D16, X8_D24, D24S8; not D32_SFLOAT,
// whose Dref is compared as given). A Dref instruction with a sampler whose compareEnable is VK_FALSE has undefined
// results ("Texel Input Operations"); vkrt then compares with the sampler's compareOp when it is a valid one (what
// the spec's note on compareEnable says some implementations do: follow the shader) and with NEVER (0.0) otherwise.
static DepthCompare depthCompare(const View& v, const VkSamplerCreateInfo& s, float dref) {
  DepthCompare c;
  c.op = s.compareOp >= VK_COMPARE_OP_NEVER && s.compareOp <= VK_COMPARE_OP_ALWAYS ? s.compareOp : VK_COMPARE_OP_NEVER;
  c.ref = v.format->type == N::UNorm ? std::clamp(dref, 0.0f, 1.0f) : dref;
  return c;
}

// sampleAtLod's fast path (fastSampling's case, no offset, no comparison): false where the generic path decides.
__attribute__((always_inline)) static inline bool fastAtLod(const View& v, const VkSamplerCreateInfo& s,
                                                            const FastView& fast, const float coord[4], float lambda,
                                                            uint32_t out[4]) {
  lambda = std::clamp(lambda, s.minLod, std::max(s.minLod, s.maxLod));
  const VkFilter filter = lambda <= 0.0f ? s.magFilter : s.minFilter;
  const float maxLevel = float(v.levelCount - 1);
  const float d = std::clamp(lambda, 0.0f, maxLevel);
  float result[4];
  if (d != d || !fastSample(fast, filter, s.mipmapMode, d, uint32_t(maxLevel), coord, arrayLayer(v, coord), result))
    return false;
  std::memcpy(out, result, 16);
  if (!fast.identity) applySwizzle(v, out);
  return true;
}

// The filtering at level of detail `lambda` (before the sampler's clamp; "Level-of-Detail Operation" then "Image
// Level(s) Selection" and "Texel Filtering"), shared by the explicit-LOD and the gradient forms; `cmp` for the Dref
// forms; `fast`: fastView's result for (v, s).
static void sampleAtLod(const View& v, const VkSamplerCreateInfo& s, const FastView* fast, const float coord[4],
                        float lambda, const int32_t* offset, const DepthCompare* cmp, uint32_t out[4]) {
  if (fast && !offset && !cmp && fastAtLod(v, s, *fast, coord, lambda, out)) return;
  lambda = std::clamp(lambda, s.minLod, std::max(s.minLod, s.maxLod));
  VkFilter filter = lambda <= 0.0f ? s.magFilter : s.minFilter;
  float maxLevel = float(v.levelCount - 1);
  float d = std::clamp(lambda, 0.0f, maxLevel);
  int64_t layer = arrayLayer(v, coord);
  float result[4];
  if (s.mipmapMode == VK_SAMPLER_MIPMAP_MODE_NEAREST || d == std::floor(d)) {
    // Nearest: level ceil(d + 0.5) - 1, i.e. d rounded with halves going down.
    uint32_t level = uint32_t(std::clamp(std::ceil(d + 0.5f) - 1.0f, 0.0f, maxLevel));
    filterLevel(v, s, filter, level, coord, layer, offset, cmp, result);
  } else {
    uint32_t lo = uint32_t(std::floor(d));
    uint32_t hi = std::min(lo + 1, uint32_t(maxLevel));
    float a[4], bb[4], t = d - std::floor(d);
    filterLevel(v, s, filter, lo, coord, layer, offset, cmp, a);
    filterLevel(v, s, filter, hi, coord, layer, offset, cmp, bb);
    for (int c = 0; c < 4; ++c) result[c] = a[c] * (1 - t) + bb[c] * t;
  }
  std::memcpy(out, result, 16);
  applySwizzle(v, out);
}

// The explicit-LOD forms: the level of detail is the Lod operand plus the sampler's bias, then the sampler's clamp.
// anisotropyEnable changes nothing here: with an explicit Lod the derivatives are zero, so the ratio of anisotropy is
// 1 ("Scale Factor Operation") and the one isotropic sample is the anisotropic filter.
static void sampleLod(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                      float lod, const float* dref, const int32_t* offset, uint32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || !smp || !smp->sampler) return;
  const VkSamplerCreateInfo& s = recordObject<Sampler>(smp->sampler)->info;
  DepthCompare cmp;
  if (dref) cmp = depthCompare(v, s, *dref);
  FastView fv;
  sampleAtLod(v, s, fastView(v, s, &fv), coord, std::isnan(lod) ? 0.0f : lod + s.mipLodBias, offset,
              dref ? &cmp : nullptr, out);
}

// "Scale Factor Operation": the derivatives scaled by the view's base level size give rho_x and rho_y (squared
// here, per lane of `ddx` / `ddy`: component i of lane l at [4 i + l]); the level of detail is log2 of the larger
// ("Level-of-Detail Operation", isotropic; sampleAnisotropic takes an anisotropic footprint of a sampler with
// anisotropyEnable): log2(rho^2) / 2, no square root; -inf for zero derivatives
// (sampleAtLod's clamp takes it to minLod), 0 for NaN.
static Float4 lodOfDerivatives(const View& v, const VkSamplerCreateInfo& s, const float* ddx, const float* ddy) {
  VkExtent3D e = levelExtent(v, 0);
  const float size[3] = {float(e.width), float(e.height), float(e.depth)};
  Float4 rx = {0, 0, 0, 0}, ry = {0, 0, 0, 0};
  for (int i = 0; i < v.dims && i < 3; ++i) {
    const float scale = s.unnormalizedCoordinates ? 1.0f : size[i];
    Float4 dx, dy;
    std::memcpy(&dx, ddx + 4 * i, 16);
    std::memcpy(&dy, ddy + 4 * i, 16);
    rx += (dx * scale) * (dx * scale);
    ry += (dy * scale) * (dy * scale);
  }
  const Float4 lambda = 0.5f * lodLog2(rx < ry ? ry : rx);  // std::max's choice: a NaN ry is passed over
  return lambda == lambda ? lambda : Float4{0, 0, 0, 0};
}

// The shader's Bias (NaN: none) and the sampler's mipLodBias added.
static float biasedLod(const VkSamplerCreateInfo& s, float lambda, float bias) {
  if (!std::isnan(bias)) lambda += bias;
  return lambda + s.mipLodBias;
}

// One lane's level of detail: the quad's computation with the lane's derivatives in lane 0.
static float gradLambda(const View& v, const VkSamplerCreateInfo& s, const float ddx[4], const float ddy[4],
                        float bias) {
  float dx[12] = {}, dy[12] = {};
  for (int i = 0; i < 3; ++i) {
    dx[4 * i] = ddx[i];
    dy[4 * i] = ddy[i];
  }
  return biasedLod(s, lodOfDerivatives(v, s, dx, dy)[0], bias);
}

// "Texel Anisotropic Filtering" for the gradient forms of a sampler with anisotropyEnable: rho_x and rho_y as
// sampleGrad computes them ("Scale Factor Operation"), the ratio eta = min(rho_max / rho_min, maxAnisotropy) (a
// line-shaped footprint, rho_min = 0, takes maxAnisotropy), and when eta > 1, N = ceil(eta) isotropic samples at
// lambda = log2(rho_max / eta) (plus the biases, then the sampler's clamp and level selection as sampleAtLod) spaced
// along the major axis's derivative at x - 1/2 + i / (N + 1), i = 1..N, and averaged: the spec's 2D scheme, applied
// to each filter and mipmap mode (and to 1D and 3D views along the same derivative). The sampler's maxAnisotropy is
// within maxSamplerAnisotropy (vkCreateSampler, VUID-VkSamplerCreateInfo-anisotropyEnable-01071). False when eta
// is 1 (the isotropic path then samples once), for integer formats (not filtered) and cube views (their own path).
static bool sampleAnisotropic(const View& v, const VkSamplerCreateInfo& s, const float coord[4], const float ddx[4],
                              const float ddy[4], float bias, const float* dref, const int32_t* offset,
                              uint32_t out[4]) {
  if (!s.anisotropyEnable || !(s.maxAnisotropy > 1.0f) || isIntFormat(*v.format)) return false;
  const VkExtent3D e = levelExtent(v, 0);
  const float size[3] = {float(e.width), float(e.height), float(e.depth)};
  float rx = 0, ry = 0;
  for (int i = 0; i < v.dims && i < 3; ++i) {
    rx += (ddx[i] * size[i]) * (ddx[i] * size[i]);
    ry += (ddy[i] * size[i]) * (ddy[i] * size[i]);
  }
  const float rhoX = std::sqrt(rx), rhoY = std::sqrt(ry);
  const float rhoMax = std::max(rhoX, rhoY), rhoMin = std::min(rhoX, rhoY);
  if (!(rhoMax > 0.0f) || !std::isfinite(rhoMax)) return false;  // a point footprint (or NaN): isotropic
  const float eta = rhoMin > 0.0f ? std::min(rhoMax / rhoMin, s.maxAnisotropy) : s.maxAnisotropy;
  if (!(eta > 1.0f)) return false;
  const uint32_t n = uint32_t(std::ceil(eta));
  const float lambda = biasedLod(s, lodLog2(Float4{} + rhoMax / eta)[0], bias);  // lodLog2: the same on every CPU
  DepthCompare cmp;
  if (dref) cmp = depthCompare(v, s, *dref);
  const float* major = rhoX > rhoY ? ddx : ddy;
  double sum[4] = {0, 0, 0, 0};
  for (uint32_t i = 1; i <= n; ++i) {
    const float t = -0.5f + float(i) / float(n + 1);
    float c[4] = {coord[0], coord[1], coord[2], coord[3]};
    for (int d = 0; d < v.dims && d < 3; ++d) c[d] = coord[d] + t * major[d];
    uint32_t r[4];
    sampleAtLod(v, s, nullptr, c, lambda, offset, dref ? &cmp : nullptr, r);
    for (int k = 0; k < 4; ++k) sum[k] += double(bitsf(r[k]));
  }
  for (int k = 0; k < 4; ++k) out[k] = fbits(float(sum[k] / double(n)));
  return true;
}

// "Scale Factor Operation": the derivatives scaled by the view's base level size give rho_x and rho_y; the level of
// detail is log2 of the larger ("Level-of-Detail Operation", isotropic; sampleAnisotropic takes the samplers with
// anisotropyEnable whose footprint is anisotropic), plus the shader's and the sampler's biases.
static void sampleGrad(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                       const float ddx[4], const float ddy[4], float bias, const float* dref, const int32_t* offset,
                       uint32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || !smp || !smp->sampler) return;
  const VkSamplerCreateInfo& s = recordObject<Sampler>(smp->sampler)->info;
  if (sampleAnisotropic(v, s, coord, ddx, ddy, bias, dref, offset, out)) return;
  DepthCompare cmp;
  if (dref) cmp = depthCompare(v, s, *dref);
  FastView fv;
  sampleAtLod(v, s, fastView(v, s, &fv), coord, gradLambda(v, s, ddx, ddy, bias), offset, dref ? &cmp : nullptr, out);
}

// "Texel Gathering": the 2 x 2 texels the LINEAR filter would weigh in the view's base level, each compared (Dref
// form), swizzled, and reduced to component `component`, as (i0 j1, i1 j1, i1 j0, i0 j0).
static void gather(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                   int32_t component, const float* dref, uint32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || !smp || !smp->sampler || v.dims != 2) return;
  const VkSamplerCreateInfo& s = recordObject<Sampler>(smp->sampler)->info;
  DepthCompare cmp;
  if (dref) cmp = depthCompare(v, s, *dref);
  VkExtent3D e = levelExtent(v, 0);
  const double size[2] = {double(e.width), double(e.height)};
  int64_t i0[2];
  for (int d = 0; d < 2; ++d)
    i0[d] = int64_t(std::floor((s.unnormalizedCoordinates ? double(coord[d]) : double(coord[d]) * size[d]) - 0.5));
  const int64_t layer = arrayLayer(v, coord);
  static constexpr int kOffsets[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  const uint32_t comp = uint32_t(component) & 3;
  for (int k = 0; k < 4; ++k) {
    uint32_t t[4];
    comparedTexel(v, s, 0, i0[0] + kOffsets[k][0], i0[1] + kOffsets[k][1], 0, layer, dref ? &cmp : nullptr, t);
    applySwizzle(v, t);
    out[k] = t[comp];
  }
}

void vkrt_image_sample(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                       float lod, uint32_t out[4]) {
  sampleLod(img, smp, coord, lod, nullptr, nullptr, out);
}

void vkrt_image_sample_offset(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                              float lod, const int32_t offset[4], uint32_t out[4]) {
  sampleLod(img, smp, coord, lod, nullptr, offset, out);
}

void vkrt_image_sample_dref(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                            float lod, float dref, const int32_t offset[4], uint32_t out[4]) {
  sampleLod(img, smp, coord, lod, &dref, offset, out);
}

void vkrt_image_sample_grad(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                            const float ddx[4], const float ddy[4], float bias, uint32_t out[4]) {
  sampleGrad(img, smp, coord, ddx, ddy, bias, nullptr, nullptr, out);
}

namespace {

// vkrt_image_sample_grad_quad's lanes the vector path left, and its view's component mapping (`lod`: their levels of
// detail); out of line, so that the vector path's call keeps a small frame.
[[gnu::noinline]] void quadSampleRest(const abi::DescriptorRecord* img, const Sampler* sp, const float coord[16],
                                      uint32_t lanes, uint32_t rest, const float lod[4], uint32_t out[16]) {
  View v;
  resolveView(img, &v);  // succeeds: the view's record is fast
  for (unsigned l = 0; l < 4; ++l) {
    if (!(lanes >> l & 1)) continue;
    uint32_t r[4] = {out[l], out[4 + l], out[8 + l], out[12 + l]};
    if (rest >> l & 1) {
      const float c[4] = {coord[l], coord[4 + l], coord[8 + l], coord[12 + l]};
      sampleAtLod(v, sp->info, nullptr, c, lod[l], nullptr, nullptr, r);
    } else {
      applySwizzle(v, r);
    }
    for (unsigned k = 0; k < 4; ++k) out[4 * k + l] = r[k];
  }
}

// The per-lane path of vkrt_image_sample_grad_quad: the view, the sampler and the per-lane fast path's decision once
// for the quad; each lane then as vkrt_image_sample_grad.
[[gnu::noinline]] void sampleGradQuadLanes(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp,
                                           const float coord[16], const float ddx[16], const float ddy[16],
                                           const float bias[4], uint32_t lanes, uint32_t out[16]) {
  std::memset(out, 0, 64);
  View v;
  if (!resolveView(img, &v) || !smp || !smp->sampler) return;
  const VkSamplerCreateInfo& s = recordObject<Sampler>(smp->sampler)->info;
  FastView fv;
  const FastView* fast = fastView(v, s, &fv);
  const Float4 lambda = lodOfDerivatives(v, s, ddx, ddy);  // the four lanes' at once
  for (unsigned l = 0; l < 4; ++l) {
    if (!(lanes >> l & 1)) continue;
    const float c[4] = {coord[l], coord[4 + l], coord[8 + l], coord[12 + l]};
    uint32_t r[4];
    // With anisotropyEnable each lane's own footprint decides, as in sampleGrad.
    const float dx[4] = {ddx[l], ddx[4 + l], ddx[8 + l], 0.0f}, dy[4] = {ddy[l], ddy[4 + l], ddy[8 + l], 0.0f};
    if (!s.anisotropyEnable || !sampleAnisotropic(v, s, c, dx, dy, bias[l], nullptr, nullptr, r)) {
      const float lod = biasedLod(s, lambda[l], bias[l]);
      if (!fast || !fastAtLod(v, s, *fast, c, lod, r)) sampleAtLod(v, s, nullptr, c, lod, nullptr, nullptr, r);
    }
    for (unsigned k = 0; k < 4; ++k) out[4 * k + l] = r[k];
  }
}

}  // namespace

void vkrt_image_sample_grad_quad(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp,
                                 const float coord[16], const float ddx[16], const float ddy[16], const float bias[4],
                                 uint32_t lanes, uint32_t out[16]) {
  // The vector path where both records say so (quad_sampling.hpp), with the lanes it leaves and the view's component
  // mapping done as vkrt_image_sample_grad does them; otherwise the per-lane path.
  if (img && img->object && smp && smp->sampler &&
      static_cast<const Object*>(img->object)->objectType == VK_OBJECT_TYPE_IMAGE_VIEW) {
    const ImageView* iv = recordObject<ImageView>(img->object);
    const Sampler* sp = recordObject<Sampler>(smp->sampler);
    if (iv->quad.fast && sp->quad.fast) {
      float lod[4];
      const uint32_t rest = sampleQuadFast(iv->quad, sp->quad, coord, ddx, ddy, bias, lanes, out, lod);
      if (rest || !iv->quad.identity) quadSampleRest(img, sp, coord, lanes, rest, lod, out);
      return;
    }
  }
  sampleGradQuadLanes(img, smp, coord, ddx, ddy, bias, lanes, out);
}

void vkrt_image_sample_grad_offset(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp,
                                   const float coord[4], const float ddx[4], const float ddy[4], float bias,
                                   const int32_t offset[4], uint32_t out[4]) {
  sampleGrad(img, smp, coord, ddx, ddy, bias, nullptr, offset, out);
}

void vkrt_image_sample_grad_dref(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp,
                                 const float coord[4], const float ddx[4], const float ddy[4], float bias, float dref,
                                 const int32_t offset[4], uint32_t out[4]) {
  sampleGrad(img, smp, coord, ddx, ddy, bias, &dref, offset, out);
}

void vkrt_image_gather(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                       int32_t component, uint32_t out[4]) {
  gather(img, smp, coord, component, nullptr, out);
}

void vkrt_image_gather_dref(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                            float dref, uint32_t out[4]) {
  gather(img, smp, coord, 0, &dref, out);
}

// ---- Cube maps ("Cube Map Face Selection and Transformations", "Cube Map Edge Handling")

// The face a direction selects and the face's (sc, tc, ma) of a vector: ma the major axis component (signed so that
// it is positive for the direction), sc and tc the two others as the spec's table orders and signs them. Ties go to
// Z, then Y (the spec leaves the choice to the implementation).
static int cubeFace(const float d[3]) {
  const float ax = std::fabs(d[0]), ay = std::fabs(d[1]), az = std::fabs(d[2]);
  if (az >= ax && az >= ay) return d[2] >= 0 ? 4 : 5;
  if (ay >= ax) return d[1] >= 0 ? 2 : 3;
  return d[0] >= 0 ? 0 : 1;
}
static void cubeAxes(int face, const float v[3], float* sc, float* tc, float* ma) {
  switch (face) {
    case 0: *sc = -v[2], *tc = -v[1], *ma = v[0]; break;    // +X
    case 1: *sc = v[2], *tc = -v[1], *ma = -v[0]; break;    // -X
    case 2: *sc = v[0], *tc = v[2], *ma = v[1]; break;      // +Y
    case 3: *sc = v[0], *tc = -v[2], *ma = -v[1]; break;    // -Y
    case 4: *sc = v[0], *tc = -v[1], *ma = v[2]; break;     // +Z
    default: *sc = -v[0], *tc = -v[1], *ma = -v[2]; break;  // -Z
  }
}
// The direction of face coordinates (sc, tc) at ma = 1: cubeAxes inverted.
static void cubeDirection(int face, float sc, float tc, float d[3]) {
  switch (face) {
    case 0: d[0] = 1, d[1] = -tc, d[2] = -sc; break;
    case 1: d[0] = -1, d[1] = -tc, d[2] = sc; break;
    case 2: d[0] = sc, d[1] = 1, d[2] = tc; break;
    case 3: d[0] = sc, d[1] = -1, d[2] = -tc; break;
    case 4: d[0] = sc, d[1] = -tc, d[2] = 1; break;
    default: d[0] = -sc, d[1] = -tc, d[2] = -1; break;
  }
}

// Texel (i, j) of `face` at `level` (size x size texels), i or j (not both) possibly past an edge of the face: then
// the texel of the adjacent face that continues it, the texel centre's direction re-projected (the spec's edge
// table, computed).
static void cubeEdgeTexel(const View& v, uint32_t level, int32_t size, int face, int64_t i, int64_t j, int64_t cube,
                          uint32_t out[4]) {
  if (i < 0 || j < 0 || i >= size || j >= size) {
    float d[3];
    cubeDirection(face, 2.0f * (float(i) + 0.5f) / float(size) - 1.0f, 2.0f * (float(j) + 0.5f) / float(size) - 1.0f,
                  d);
    face = cubeFace(d);
    float sc, tc, ma;
    cubeAxes(face, d, &sc, &tc, &ma);
    i = std::clamp<int64_t>(int64_t(std::floor(0.5f * (sc / ma + 1.0f) * float(size))), 0, size - 1);
    j = std::clamp<int64_t>(int64_t(std::floor(0.5f * (tc / ma + 1.0f) * float(size))), 0, size - 1);
  }
  const int64_t xyzl[4] = {i, j, 0, cube * 6 + face};
  readTexel(v, level, xyzl, out);
}

// Texel (i, j) of `face` at `level`, compared with `cmp` when given, past an edge as cubeEdgeTexel. Past a corner
// (both i and j outside the face) no face continues the texel: "Cube Map Corner Texel" says it should be the average
// of the three texels that meet at the cube's corner, the face's own corner texel and its two neighbours across
// the edges. The average is taken in double, so three equal values average to that value exactly (the spec's
// constraint on any corner method); the depth comparison applies to the averaged texel. Integer formats (only
// gathers read their corners) keep the face's own corner texel, which meets the same constraint.
static void cubeTexel(const View& v, uint32_t level, int32_t size, int face, int64_t i, int64_t j, int64_t cube,
                      const DepthCompare* cmp, uint32_t out[4]) {
  const int64_t ci = std::clamp<int64_t>(i, 0, size - 1), cj = std::clamp<int64_t>(j, 0, size - 1);
  if (ci != i && cj != j) {
    if (isIntFormat(*v.format)) {
      cubeEdgeTexel(v, level, size, face, ci, cj, cube, out);
    } else {
      uint32_t t[3][4];
      cubeEdgeTexel(v, level, size, face, ci, cj, cube, t[0]);
      cubeEdgeTexel(v, level, size, face, i, cj, cube, t[1]);
      cubeEdgeTexel(v, level, size, face, ci, j, cube, t[2]);
      for (int c = 0; c < 4; ++c)
        out[c] = fbits(float((double(bitsf(t[0][c])) + double(bitsf(t[1][c])) + double(bitsf(t[2][c]))) / 3.0));
    }
  } else {
    cubeEdgeTexel(v, level, size, face, i, j, cube, out);
  }
  if (cmp) out[0] = fbits(compareDepth(*cmp, bitsf(out[0])));
}

// Filters one level of face `face` at face coordinates (s, t) in [0, 1].
static void cubeFilterLevel(const View& v, VkFilter filter, uint32_t level, int face, float s, float t, int64_t cube,
                            const DepthCompare* cmp, float out[4]) {
  const int32_t size = int32_t(levelExtent(v, level).width);
  const double u = double(s) * size, w = double(t) * size;
  uint32_t tx[4][4];
  if (filter == VK_FILTER_NEAREST || isIntFormat(*v.format)) {
    cubeTexel(v, level, size, face, std::clamp<int64_t>(int64_t(std::floor(u)), 0, size - 1),
              std::clamp<int64_t>(int64_t(std::floor(w)), 0, size - 1), cube, cmp, tx[0]);
    std::memcpy(out, tx[0], 16);
    return;
  }
  const int64_t i0 = int64_t(std::floor(u - 0.5)), j0 = int64_t(std::floor(w - 0.5));
  const double a = (u - 0.5) - std::floor(u - 0.5), b = (w - 0.5) - std::floor(w - 0.5);
  const double weight[4] = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
  for (int k = 0; k < 4; ++k) cubeTexel(v, level, size, face, i0 + (k & 1), j0 + (k >> 1), cube, cmp, tx[k]);
  for (int c = 0; c < 4; ++c) {
    double acc = 0;
    for (int k = 0; k < 4; ++k) acc += weight[k] * double(bitsf(tx[k][c]));
    out[c] = float(acc);
  }
}

// The face, (s, t) and cube index of a cube sampling coordinate; false for a view that is not a cube (array) or a
// direction of zero length or not finite (then the result is zeros).
static bool cubeCoord(const View& v, const float coord[4], int* face, float* s, float* t, float* ma, int64_t* cube) {
  if (v.view->viewType != VK_IMAGE_VIEW_TYPE_CUBE && v.view->viewType != VK_IMAGE_VIEW_TYPE_CUBE_ARRAY) return false;
  if (v.layerCount < 6) return false;
  *face = cubeFace(coord);
  float sc, tc;
  cubeAxes(*face, coord, &sc, &tc, ma);
  if (!(*ma > 0) || !std::isfinite(*ma)) return false;
  *s = 0.5f * (sc / *ma + 1.0f);
  *t = 0.5f * (tc / *ma + 1.0f);
  *cube = 0;
  if (v.view->viewType == VK_IMAGE_VIEW_TYPE_CUBE_ARRAY) {
    const float l = std::nearbyint(coord[3]);
    *cube = int64_t(std::clamp(std::isnan(l) ? 0.0f : l, 0.0f, float(v.layerCount / 6 - 1)));
  }
  return true;
}

// What both cube entry points start from: the view and sampler, the face, (s, t), ma and cube of the coordinate,
// and the depth comparison (Dref forms); false when the result is zeros (out is cleared).
struct CubeLookup {
  View v;
  const VkSamplerCreateInfo* sampler = nullptr;
  int face = 0;
  float s = 0, t = 0, ma = 0;
  int64_t cube = 0;
  DepthCompare cmp;
  const DepthCompare* compare = nullptr;  // &cmp with kCubeDref
};
static bool cubeLookup(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                       float dref, uint32_t flags, uint32_t out[4], CubeLookup* c) {
  std::memset(out, 0, 16);
  if (!resolveView(img, &c->v) || !smp || !smp->sampler) return false;
  c->sampler = &recordObject<Sampler>(smp->sampler)->info;
  if (!cubeCoord(c->v, coord, &c->face, &c->s, &c->t, &c->ma, &c->cube)) return false;
  if (flags & abi::kCubeDref) {
    c->cmp = depthCompare(c->v, *c->sampler, dref);
    c->compare = &c->cmp;
  }
  return true;
}

void vkrt_image_sample_cube(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                            const float ddx[4], const float ddy[4], float lod, float dref, uint32_t flags,
                            uint32_t out[4]) {
  CubeLookup l;
  if (!cubeLookup(img, smp, coord, dref, flags, out, &l)) return;
  const View& v = l.v;
  const VkSamplerCreateInfo& smpInfo = *l.sampler;
  const int face = l.face;
  const float s = l.s, t = l.t, ma = l.ma;
  const int64_t cube = l.cube;
  float lambda;
  if (flags & abi::kCubeGrad) {
    // "Cube Map Derivation": d(s)/dx = 1/2 (d(sc)/dx / ma - sc d(ma)/dx / ma^2), likewise t and y; then the scale
    // factors and the level of detail as for 2D ("Scale Factor Operation", "Level-of-Detail Operation").
    float sc, tc, m;
    cubeAxes(face, coord, &sc, &tc, &m);
    const float size = float(levelExtent(v, 0).width);
    float rho2[2];
    for (int k = 0; k < 2; ++k) {
      float dsc, dtc, dma;
      cubeAxes(face, k ? ddy : ddx, &dsc, &dtc, &dma);
      const float ds = 0.5f * (dsc / ma - sc * dma / (ma * ma)) * size;
      const float dt = 0.5f * (dtc / ma - tc * dma / (ma * ma)) * size;
      rho2[k] = ds * ds + dt * dt;
    }
    lambda = 0.5f * std::log2(std::max(rho2[0], rho2[1]));  // -inf for zero derivatives: clamped to minLod below
    if (std::isnan(lambda)) lambda = 0.0f;
    if (!std::isnan(lod)) lambda += lod;
  } else {
    lambda = std::isnan(lod) ? 0.0f : lod;
  }
  lambda += smpInfo.mipLodBias;
  const DepthCompare* c = l.compare;
  // "Level-of-Detail Operation" and "Image Level(s) Selection", as sampleAtLod.
  lambda = std::clamp(lambda, smpInfo.minLod, std::max(smpInfo.minLod, smpInfo.maxLod));
  const VkFilter filter = lambda <= 0.0f ? smpInfo.magFilter : smpInfo.minFilter;
  const float maxLevel = float(v.levelCount - 1);
  const float d = std::clamp(lambda, 0.0f, maxLevel);
  float result[4];
  if (smpInfo.mipmapMode == VK_SAMPLER_MIPMAP_MODE_NEAREST || d == std::floor(d)) {
    const uint32_t level = uint32_t(std::clamp(std::ceil(d + 0.5f) - 1.0f, 0.0f, maxLevel));
    cubeFilterLevel(v, filter, level, face, s, t, cube, c, result);
  } else {
    const uint32_t lo = uint32_t(std::floor(d)), hi = std::min(lo + 1, uint32_t(maxLevel));
    float a[4], b[4];
    const float f = d - std::floor(d);
    cubeFilterLevel(v, filter, lo, face, s, t, cube, c, a);
    cubeFilterLevel(v, filter, hi, face, s, t, cube, c, b);
    for (int k = 0; k < 4; ++k) result[k] = a[k] * (1 - f) + b[k] * f;
  }
  std::memcpy(out, result, 16);
  applySwizzle(v, out);
}

void vkrt_image_gather_cube(const abi::DescriptorRecord* img, const abi::DescriptorRecord* smp, const float coord[4],
                            int32_t component, float dref, uint32_t flags, uint32_t out[4]) {
  CubeLookup l;
  if (!cubeLookup(img, smp, coord, dref, flags, out, &l)) return;
  const View& v = l.v;
  const int64_t cube = l.cube;
  const int face = l.face;
  const float s = l.s, t = l.t;
  const int32_t size = int32_t(levelExtent(v, 0).width);
  const int64_t i0 = int64_t(std::floor(double(s) * size - 0.5)), j0 = int64_t(std::floor(double(t) * size - 0.5));
  // (i0 j1, i1 j1, i1 j0, i0 j0), as vkrt_image_gather.
  static constexpr int kOffsets[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  const uint32_t comp = (flags & abi::kCubeDref) ? 0 : uint32_t(component) & 3;
  for (int k = 0; k < 4; ++k) {
    uint32_t tx[4];
    cubeTexel(v, 0, size, face, i0 + kOffsets[k][0], j0 + kOffsets[k][1], cube, l.compare, tx);
    applySwizzle(v, tx);
    out[k] = tx[comp];
  }
}

void vkrt_image_size(const abi::DescriptorRecord* img, int32_t lod, int32_t out[4]) {
  View v;
  std::memset(out, 0, 16);
  if (!resolveView(img, &v) || lod < 0 || uint32_t(lod) >= v.levelCount) return;
  VkExtent3D e = levelExtent(v, uint32_t(lod));
  int32_t dims[3] = {int32_t(e.width), int32_t(e.height), int32_t(e.depth)};
  for (int i = 0; i < v.dims; ++i) out[i] = dims[i];
  if (v.arrayed) {
    uint32_t layers = v.layerCount;
    if (v.view->viewType == VK_IMAGE_VIEW_TYPE_CUBE) layers = 0;
    if (v.view->viewType == VK_IMAGE_VIEW_TYPE_CUBE_ARRAY) layers /= 6;
    if (layers) out[v.dims] = int32_t(layers);
  }
}

int32_t vkrt_image_levels(const abi::DescriptorRecord* img) {
  View v;
  return resolveView(img, &v) ? int32_t(v.levelCount) : 0;
}

// Texel buffers: a buffer view has no component mapping (texels come back as the format decodes them) and no
// levels; an index outside the view reads zeros and writes nothing, as robustBufferAccess allows.
void vkrt_texel_buffer_read(const abi::DescriptorRecord* buf, int64_t index, uint32_t out[4]) {
  TexelBuffer t;
  std::memset(out, 0, 16);
  if (!resolveTexelBuffer(buf, &t)) return;
  if (const uint8_t* p = texelAt(t, index)) decodeTexel(*t.format, p, out);
}

void vkrt_texel_buffer_write(const abi::DescriptorRecord* buf, int64_t index, const uint32_t in[4]) {
  TexelBuffer t;
  if (!resolveTexelBuffer(buf, &t)) return;
  if (uint8_t* p = texelAt(t, index)) encodeTexel(*t.format, in, p);
}

void* vkrt_texel_buffer_texel(const abi::DescriptorRecord* buf, int64_t index) {
  TexelBuffer t;
  if (!resolveTexelBuffer(buf, &t) || t.format->texelSize != 4) return nullptr;  // atomics: 32-bit formats only
  return texelAt(t, index);
}

int32_t vkrt_texel_buffer_size(const abi::DescriptorRecord* buf) {
  TexelBuffer t;
  // maxTexelBufferElements (2^27) bounds a view's texel count, so it fits the shader's 32-bit integer.
  return resolveTexelBuffer(buf, &t) ? int32_t(t.texels) : 0;
}

// VKRT_SHADER_CHECKS=image (abi/shader_debug.hpp; debug3): the report of an access that the functions above treat as
// outside the view (through the same resolveView, splitCoord and texelAt); they read zeros and write nothing there. A
// null or mismatched descriptor is not a coordinate out of range: not reported here.
void vkrt_check_image(abi::InvocationContext* ctx, const uint8_t* site, const abi::DescriptorRecord* img,
                      const int32_t coord[4], int32_t lod, uint64_t element) {
  View v;
  if (!resolveView(img, &v)) return;
  int64_t c[4] = {coord[0], coord[1], coord[2], coord[3]}, xyzl[4];
  splitCoord(v, c, xyzl);
  if (lod >= 0 && texelAt(v, uint32_t(lod), xyzl[0], xyzl[1], xyzl[2], xyzl[3])) return;
  exec::Job* job = exec::runningJob();
  if (!job) return;
  exec::OutOfBoundsRecord r;
  r.site = site;
  r.element = element;
  for (int i = 0; i < 4; ++i) r.coord[i] = xyzl[i];
  r.coord[4] = lod;
  r.extent[3] = v.layerCount;
  if (lod >= 0 && uint32_t(lod) < v.levelCount) {
    VkExtent3D e = levelExtent(v, uint32_t(lod));
    r.extent[0] = e.width;
    r.extent[1] = e.height;
    r.extent[2] = e.depth;
    if (v.slicesAsLayers) {
      uint32_t depth = v.image->mips[v.baseMip + uint32_t(lod)].extent.depth;
      r.extent[3] = std::min<uint64_t>(v.layerCount, depth > v.baseLayer ? depth - v.baseLayer : 0);
    }
  }
  r.extent[4] = v.levelCount;
  job->messages.outOfBounds(ctx, r);
}

void vkrt_check_texel_buffer(abi::InvocationContext* ctx, const uint8_t* site, const abi::DescriptorRecord* buf,
                             int64_t index, uint64_t element) {
  TexelBuffer t;
  if (!resolveTexelBuffer(buf, &t) || texelAt(t, index)) return;
  exec::Job* job = exec::runningJob();
  if (!job) return;
  exec::OutOfBoundsRecord r;
  r.site = site;
  r.element = element;
  r.coord[0] = index;
  r.extent[0] = uint64_t(t.texels);
  job->messages.outOfBounds(ctx, r);
}

}  // extern "C"

namespace vkrt {

const abi::HostSymbol* imageFunctionSymbols() {
  static const abi::HostSymbol symbols[] = {
      {"vkrt_image_read", reinterpret_cast<void*>(&vkrt_image_read)},
      {"vkrt_image_read_subpass", reinterpret_cast<void*>(&vkrt_image_read_subpass)},
      {"vkrt_image_write", reinterpret_cast<void*>(&vkrt_image_write)},
      {"vkrt_image_texel", reinterpret_cast<void*>(&vkrt_image_texel)},
      {"vkrt_image_fetch", reinterpret_cast<void*>(&vkrt_image_fetch)},
      {"vkrt_image_sample", reinterpret_cast<void*>(&vkrt_image_sample)},
      {"vkrt_image_sample_grad", reinterpret_cast<void*>(&vkrt_image_sample_grad)},
      {"vkrt_image_sample_grad_quad", reinterpret_cast<void*>(&vkrt_image_sample_grad_quad)},
      {"vkrt_image_sample_offset", reinterpret_cast<void*>(&vkrt_image_sample_offset)},
      {"vkrt_image_sample_grad_offset", reinterpret_cast<void*>(&vkrt_image_sample_grad_offset)},
      {"vkrt_image_sample_dref", reinterpret_cast<void*>(&vkrt_image_sample_dref)},
      {"vkrt_image_sample_grad_dref", reinterpret_cast<void*>(&vkrt_image_sample_grad_dref)},
      {"vkrt_image_gather", reinterpret_cast<void*>(&vkrt_image_gather)},
      {"vkrt_image_gather_dref", reinterpret_cast<void*>(&vkrt_image_gather_dref)},
      {"vkrt_image_sample_cube", reinterpret_cast<void*>(&vkrt_image_sample_cube)},
      {"vkrt_image_gather_cube", reinterpret_cast<void*>(&vkrt_image_gather_cube)},
      {"vkrt_image_size", reinterpret_cast<void*>(&vkrt_image_size)},
      {"vkrt_image_levels", reinterpret_cast<void*>(&vkrt_image_levels)},
      {"vkrt_texel_buffer_read", reinterpret_cast<void*>(&vkrt_texel_buffer_read)},
      {"vkrt_texel_buffer_write", reinterpret_cast<void*>(&vkrt_texel_buffer_write)},
      {"vkrt_texel_buffer_texel", reinterpret_cast<void*>(&vkrt_texel_buffer_texel)},
      {"vkrt_texel_buffer_size", reinterpret_cast<void*>(&vkrt_texel_buffer_size)},
      // Shader debugging (abi/shader_debug.hpp; exec/shader_debug.cpp collects, runtime/shader_messages.cpp delivers).
      {"vkrt_debug_printf", reinterpret_cast<void*>(&vkrt_debug_printf)},
      {"vkrt_out_of_bounds", reinterpret_cast<void*>(&vkrt_out_of_bounds)},
      {"vkrt_address_table", reinterpret_cast<void*>(&vkrt_address_table)},
      {"vkrt_check_address", reinterpret_cast<void*>(&vkrt_check_address)},
      {"vkrt_check_image", reinterpret_cast<void*>(&vkrt_check_image)},
      {"vkrt_check_texel_buffer", reinterpret_cast<void*>(&vkrt_check_texel_buffer)},
      {nullptr, nullptr},
  };
  return symbols;
}

}  // namespace vkrt
