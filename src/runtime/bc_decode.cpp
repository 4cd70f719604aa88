#include "runtime/bc_decode.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

// Table names below are those of the Khronos Data Format Specification (1.3; 1.4 has the same tables). The BPTC
// tables were transcribed from the specification's source and checked by script, entry by entry, against its other
// tables (BC6H's per-bit layout tables, the anchors printed in the partition tables) and against DirectXTex's
// BC6HBC7.cpp; the decoder matched bcdec bit for bit on 400000 random BC6H and BC7 blocks.

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

// ---- BPTC: partitions, anchors and weights shared by BC7 and BC6H ----

// "Partition table for 2-subset BPTC": bit i is the subset of texel i (i = x + 4 * y). BC6H uses the first 32.
constexpr uint16_t kPartitions2[64] = {
    0xcccc, 0x8888, 0xeeee, 0xecc8, 0xc880, 0xfeec, 0xfec8, 0xec80, 0xc800, 0xffec, 0xfe80, 0xe800, 0xffe8,
    0xff00, 0xfff0, 0xf000, 0xf710, 0x008e, 0x7100, 0x08ce, 0x008c, 0x7310, 0x3100, 0x8cce, 0x088c, 0x3110,
    0x6666, 0x366c, 0x17e8, 0x0ff0, 0x718e, 0x399c, 0xaaaa, 0xf0f0, 0x5a5a, 0x33cc, 0x3c3c, 0x55aa, 0x9696,
    0xa55a, 0x73ce, 0x13c8, 0x324c, 0x3bdc, 0x6996, 0xc33c, 0x9966, 0x0660, 0x0272, 0x04e4, 0x4e40, 0x2720,
    0xc936, 0x936c, 0x39c6, 0x639c, 0x9336, 0x9cc6, 0x817e, 0xe718, 0xccf0, 0x0fcc, 0x7744, 0xee22,
};

// "Partition table for 3-subset BPTC": bits 2i..2i+1 are the subset of texel i.
constexpr uint32_t kPartitions3[64] = {
    0xaa685050, 0x6a5a5040, 0x5a5a4200, 0x5450a0a8, 0xa5a50000, 0xa0a05050, 0x5555a0a0, 0x5a5a5050,
    0xaa550000, 0xaa555500, 0xaaaa5500, 0x90909090, 0x94949494, 0xa4a4a4a4, 0xa9a59450, 0x2a0a4250,
    0xa5945040, 0x0a425054, 0xa5a5a500, 0x55a0a0a0, 0xa8a85454, 0x6a6a4040, 0xa4a45000, 0x1a1a0500,
    0x0050a4a4, 0xaaa59090, 0x14696914, 0x69691400, 0xa08585a0, 0xaa821414, 0x50a4a450, 0x6a5a0200,
    0xa9a58000, 0x5090a0a8, 0xa8a09050, 0x24242424, 0x00aa5500, 0x24924924, 0x24499224, 0x50a50a50,
    0x500aa550, 0xaaaa4444, 0x66660000, 0xa5a0a5a0, 0x50a050a0, 0x69286928, 0x44aaaa44, 0x66666600,
    0xaa444444, 0x54a854a8, 0x95809580, 0x96969600, 0xa85454a8, 0x80959580, 0xaa141414, 0x96960000,
    0xaaaa1414, 0xa05050a0, 0xa0a5a5a0, 0x96000000, 0x40804080, 0xa9a8a9a8, 0xaaaaaa44, 0x2a4a5254,
};

// "BPTC anchor index values for the second subset of two-subset partitioning". (1.4's partition table prints
// partition 35's anchor in bold at index 2; this table, DirectXTex and ARB_texture_compression_bptc say 8.)
constexpr uint8_t kAnchor2[64] = {
    15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 2,  8, 2,  2, 8,
    8,  15, 2,  8,  2,  2,  8,  8,  2,  2,  15, 15, 6,  8,  2,  8,  15, 15, 2, 8,  2, 2,
    2,  15, 15, 6,  6,  2,  6,  8,  15, 15, 2,  2,  15, 15, 15, 15, 15, 2,  2, 15,
};
// "... for the second subset of three-subset partitioning".
constexpr uint8_t kAnchor3Second[64] = {
    3, 3,  15, 15, 8, 3,  15, 15, 8,  8, 6,  6, 6,  5,  3,  3,  3, 3,  8, 15, 3, 3, 6, 10, 5, 8,  8, 6,  8,  5,  15, 15,
    8, 15, 3,  5,  6, 10, 8,  15, 15, 3, 15, 5, 15, 15, 15, 15, 3, 15, 5, 5,  5, 8, 5, 10, 5, 10, 8, 13, 15, 12, 3,  3,
};
// "... for the third subset of three-subset partitioning".
constexpr uint8_t kAnchor3Third[64] = {
    15, 8, 8, 3,  15, 15, 3,  8,  15, 15, 15, 15, 15, 15, 15, 8,  15, 8,  15, 3,  15, 8,
    15, 8, 3, 15, 6,  10, 15, 15, 10, 8,  15, 3,  15, 10, 10, 8,  9,  10, 6,  15, 8,  15,
    3,  6, 6, 8,  15, 3,  15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 3,  15, 15, 8,
};

// "BPTC interpolation factors", by index bits.
constexpr uint8_t kWeights2[4] = {0, 21, 43, 64};
constexpr uint8_t kWeights3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
constexpr uint8_t kWeights4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};

uint32_t weight(uint32_t indexBits, uint32_t index) {
  return indexBits == 2 ? kWeights2[index] : indexBits == 3 ? kWeights3[index] : kWeights4[index];
}

// "BPTC endpoint interpolation formula" (arithmetic shift for BC6H's signed endpoints).
int32_t interpolate(int32_t e0, int32_t e1, uint32_t w) { return ((64 - int32_t(w)) * e0 + int32_t(w) * e1 + 32) >> 6; }

// The subset of texel i in a block of `subsets` subsets with partition `partition`.
uint32_t subsetOf(uint32_t subsets, uint32_t partition, uint32_t i) {
  if (subsets == 2) return (kPartitions2[partition] >> i) & 1;
  if (subsets == 3) return (kPartitions3[partition] >> (2 * i)) & 3;
  return 0;
}

// Whether texel i holds an anchor index (one bit shorter: its top bit is implied zero).
bool isAnchor(uint32_t subsets, uint32_t partition, uint32_t i) {
  if (i == 0) return true;
  if (subsets == 2) return i == kAnchor2[partition];
  if (subsets == 3) return i == kAnchor3Second[partition] || i == kAnchor3Third[partition];
  return false;
}

// Reads the 16 indices of `bits` bits each from the cursor, anchors one bit shorter, in texel order.
void readIndices(Bits& in, uint32_t subsets, uint32_t partition, uint32_t bits, uint8_t out[16]) {
  for (uint32_t i = 0; i < 16; ++i) out[i] = uint8_t(in.read(bits - (isAnchor(subsets, partition, i) ? 1 : 0)));
}

// ---- BPTC: BC7 ----

// "Mode-dependent BPTC parameters": NS, PB, RB, ISB, CB, AB, EPB, SPB, IB, IB2.
struct Bc7Mode {
  uint8_t subsets, partitionBits, rotationBits, indexSelectionBits, colorBits, alphaBits, endpointPBits, sharedPBits,
      indexBits, secondaryIndexBits;
};
constexpr Bc7Mode kBc7Modes[8] = {
    {3, 4, 0, 0, 4, 0, 1, 0, 3, 0}, {2, 6, 0, 0, 6, 0, 0, 1, 3, 0}, {3, 6, 0, 0, 5, 0, 0, 0, 2, 0},
    {2, 6, 0, 0, 7, 0, 1, 0, 2, 0}, {1, 0, 2, 1, 5, 6, 0, 0, 2, 3}, {1, 0, 2, 0, 7, 8, 0, 0, 2, 2},
    {1, 0, 0, 0, 7, 7, 1, 0, 4, 0}, {2, 6, 0, 0, 5, 5, 1, 0, 2, 0},
};

// An n-bit value (n >= 4) widened to 8 bits by replicating its top bits into the low ones.
uint32_t widen8(uint32_t v, uint32_t n) { return n >= 8 ? v : (v << (8 - n)) | (v >> (2 * n - 8)); }

void decodeBc7(const uint8_t* block, float out[16][4]) {
  if (block[0] == 0) {  // no mode bit: reserved, all channels zero
    for (int i = 0; i < 16; ++i) setTexel(out[i], 0, 0, 0, 0);
    return;
  }
  uint32_t mode = 0;
  while (!(block[0] & (1u << mode))) ++mode;
  const Bc7Mode& m = kBc7Modes[mode];
  Bits in(block, 16);
  in.read(mode + 1);
  uint32_t partition = in.read(m.partitionBits);
  uint32_t rotation = in.read(m.rotationBits);
  uint32_t indexSelection = in.read(m.indexSelectionBits);
  uint32_t endpoints = 2 * m.subsets;
  // Endpoints grouped by channel, then subset, then endpoint: e = 2 * subset + endpoint.
  uint32_t ep[6][4];
  for (uint32_t ch = 0; ch < 3; ++ch)
    for (uint32_t e = 0; e < endpoints; ++e) ep[e][ch] = in.read(m.colorBits);
  for (uint32_t e = 0; e < endpoints; ++e) ep[e][3] = in.read(m.alphaBits);
  uint32_t pbit[6] = {};
  bool hasP = m.endpointPBits || m.sharedPBits;
  if (m.endpointPBits)
    for (uint32_t e = 0; e < endpoints; ++e) pbit[e] = in.read(1);
  if (m.sharedPBits)
    for (uint32_t s = 0; s < m.subsets; ++s) pbit[2 * s] = pbit[2 * s + 1] = in.read(1);
  for (uint32_t e = 0; e < endpoints; ++e) {
    for (uint32_t ch = 0; ch < 4; ++ch) {
      uint32_t n = ch < 3 ? m.colorBits : m.alphaBits;
      if (n == 0) {
        ep[e][ch] = 255;
        continue;
      }
      uint32_t v = ep[e][ch];
      if (hasP) v = (v << 1) | pbit[e], ++n;  // the P-bit sits below the stored bits, alpha included
      ep[e][ch] = widen8(v, n);
    }
  }
  uint8_t primary[16], secondary[16] = {};
  readIndices(in, m.subsets, partition, m.indexBits, primary);
  if (m.secondaryIndexBits) readIndices(in, 1, 0, m.secondaryIndexBits, secondary);
  // Colour from the secondary indices when the index selection bit is 1; alpha from them when the mode has them
  // and the bit is 0 (or absent); the primary ones otherwise.
  bool colorSecondary = indexSelection == 1;
  bool alphaSecondary = m.secondaryIndexBits && indexSelection == 0;
  uint32_t colorBits = colorSecondary ? m.secondaryIndexBits : m.indexBits;
  uint32_t alphaBits = alphaSecondary ? m.secondaryIndexBits : m.indexBits;
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t s = subsetOf(m.subsets, partition, i);
    const uint32_t* e0 = ep[2 * s];
    const uint32_t* e1 = ep[2 * s + 1];
    uint32_t wc = weight(colorBits, colorSecondary ? secondary[i] : primary[i]);
    uint32_t wa = weight(alphaBits, alphaSecondary ? secondary[i] : primary[i]);
    int32_t c[4];
    for (int ch = 0; ch < 3; ++ch) c[ch] = interpolate(int32_t(e0[ch]), int32_t(e1[ch]), wc);
    c[3] = interpolate(int32_t(e0[3]), int32_t(e1[3]), wa);
    if (rotation) std::swap(c[3], c[rotation - 1]);  // "BPTC Rotation bits": 1 swaps A and R, 2 A and G, 3 A and B
    setTexel(out[i], float(c[0]) / 255.0f, float(c[1]) / 255.0f, float(c[2]) / 255.0f, float(c[3]) / 255.0f);
  }
}

// ---- BPTC: BC6H ----

// Fields of "Block descriptions for BC6H block modes": endpoint e's channel ch is field 3 * e + ch.
enum Bc6Field : uint8_t { R0, G0, B0, R1, G1, B1, R2, G2, B2, R3, G3, B3, PB };

// count bits of the block, in order, into bits shift..shift + count - 1 of field; reversed: the first bit read
// goes to the highest of them (the spec's v^a..b with a < b).
struct Bc6Segment {
  uint8_t field, shift, count;
  bool reversed = false;
};

struct Bc6Mode {
  bool valid;
  bool transformed;
  uint8_t regions;       // 1 or 2 (two-region modes have partition bits)
  uint8_t endpointBits;  // EPB
  uint8_t deltaBits[3];  // per channel, for transformed modes
  uint8_t segmentCount;
  Bc6Segment segments[24];  // after the mode bits
};

// "Endpoint and partition parameters for BPTC block modes" with each mode's layout, indexed by the mode number
// (the low 2 bits when they are 0 or 1, else the low 5 bits); 19, 23, 27 and 31 (and the unused numbers with
// low bits 0 or 1 above them) are not valid.
constexpr Bc6Mode bc6Mode(uint32_t m) {
  switch (m) {
    case 0:
      return {true, true, 2, 10, {5, 5, 5}, 20, {{G2, 4, 1},  {B2, 4, 1}, {B3, 4, 1}, {R0, 0, 10}, {G0, 0, 10},
                                                 {B0, 0, 10}, {R1, 0, 5}, {G3, 4, 1}, {G2, 0, 4},  {G1, 0, 5},
                                                 {B3, 0, 1},  {G3, 0, 4}, {B1, 0, 5}, {B3, 1, 1},  {B2, 0, 4},
                                                 {R2, 0, 5},  {B3, 2, 1}, {R3, 0, 5}, {B3, 3, 1},  {PB, 0, 5}}};
    case 1:
      return {
          true, true, 2, 7, {6, 6, 6}, 24, {{G2, 5, 1}, {G3, 4, 1}, {G3, 5, 1}, {R0, 0, 7}, {B3, 0, 1}, {B3, 1, 1},
                                            {B2, 4, 1}, {G0, 0, 7}, {B2, 5, 1}, {B3, 2, 1}, {G2, 4, 1}, {B0, 0, 7},
                                            {B3, 3, 1}, {B3, 5, 1}, {B3, 4, 1}, {R1, 0, 6}, {G2, 0, 4}, {G1, 0, 6},
                                            {G3, 0, 4}, {B1, 0, 6}, {B2, 0, 4}, {R2, 0, 6}, {R3, 0, 6}, {PB, 0, 5}}};
    case 2:
      return {true,
              true,
              2,
              11,
              {5, 4, 4},
              19,
              {{R0, 0, 10},
               {G0, 0, 10},
               {B0, 0, 10},
               {R1, 0, 5},
               {R0, 10, 1},
               {G2, 0, 4},
               {G1, 0, 4},
               {G0, 10, 1},
               {B3, 0, 1},
               {G3, 0, 4},
               {B1, 0, 4},
               {B0, 10, 1},
               {B3, 1, 1},
               {B2, 0, 4},
               {R2, 0, 5},
               {B3, 2, 1},
               {R3, 0, 5},
               {B3, 3, 1},
               {PB, 0, 5}}};
    case 6:
      return {true, true, 2, 11, {4, 5, 4}, 21, {{R0, 0, 10}, {G0, 0, 10}, {B0, 0, 10}, {R1, 0, 4},  {R0, 10, 1},
                                                 {G3, 4, 1},  {G2, 0, 4},  {G1, 0, 5},  {G0, 10, 1}, {G3, 0, 4},
                                                 {B1, 0, 4},  {B0, 10, 1}, {B3, 1, 1},  {B2, 0, 4},  {R2, 0, 4},
                                                 {B3, 0, 1},  {B3, 2, 1},  {R3, 0, 4},  {G2, 4, 1},  {B3, 3, 1},
                                                 {PB, 0, 5}}};
    case 10:
      return {
          true, true, 2, 11, {4, 4, 5}, 21, {{R0, 0, 10}, {G0, 0, 10}, {B0, 0, 10}, {R1, 0, 4}, {R0, 10, 1}, {B2, 4, 1},
                                             {G2, 0, 4},  {G1, 0, 4},  {G0, 10, 1}, {B3, 0, 1}, {G3, 0, 4},  {B1, 0, 5},
                                             {B0, 10, 1}, {B2, 0, 4},  {R2, 0, 4},  {B3, 1, 1}, {B3, 2, 1},  {R3, 0, 4},
                                             {B3, 4, 1},  {B3, 3, 1},  {PB, 0, 5}}};
    case 14:
      return {true, true, 2, 9, {5, 5, 5}, 20, {{R0, 0, 9}, {B2, 4, 1}, {G0, 0, 9}, {G2, 4, 1}, {B0, 0, 9},
                                                {B3, 4, 1}, {R1, 0, 5}, {G3, 4, 1}, {G2, 0, 4}, {G1, 0, 5},
                                                {B3, 0, 1}, {G3, 0, 4}, {B1, 0, 5}, {B3, 1, 1}, {B2, 0, 4},
                                                {R2, 0, 5}, {B3, 2, 1}, {R3, 0, 5}, {B3, 3, 1}, {PB, 0, 5}}};
    case 18:
      return {true, true, 2, 8, {6, 5, 5}, 20, {{R0, 0, 8}, {G3, 4, 1}, {B2, 4, 1}, {G0, 0, 8}, {B3, 2, 1},
                                                {G2, 4, 1}, {B0, 0, 8}, {B3, 3, 1}, {B3, 4, 1}, {R1, 0, 6},
                                                {G2, 0, 4}, {G1, 0, 5}, {B3, 0, 1}, {G3, 0, 4}, {B1, 0, 5},
                                                {B3, 1, 1}, {B2, 0, 4}, {R2, 0, 6}, {R3, 0, 6}, {PB, 0, 5}}};
    case 22:
      return {true, true, 2, 8, {5, 6, 5}, 22, {{R0, 0, 8}, {B3, 0, 1}, {B2, 4, 1}, {G0, 0, 8}, {G2, 5, 1}, {G2, 4, 1},
                                                {B0, 0, 8}, {G3, 5, 1}, {B3, 4, 1}, {R1, 0, 5}, {G3, 4, 1}, {G2, 0, 4},
                                                {G1, 0, 6}, {G3, 0, 4}, {B1, 0, 5}, {B3, 1, 1}, {B2, 0, 4}, {R2, 0, 5},
                                                {B3, 2, 1}, {R3, 0, 5}, {B3, 3, 1}, {PB, 0, 5}}};
    case 26:
      return {true, true, 2, 8, {5, 5, 6}, 22, {{R0, 0, 8}, {B3, 1, 1}, {B2, 4, 1}, {G0, 0, 8}, {B2, 5, 1}, {G2, 4, 1},
                                                {B0, 0, 8}, {B3, 5, 1}, {B3, 4, 1}, {R1, 0, 5}, {G3, 4, 1}, {G2, 0, 4},
                                                {G1, 0, 5}, {B3, 0, 1}, {G3, 0, 4}, {B1, 0, 6}, {B2, 0, 4}, {R2, 0, 5},
                                                {B3, 2, 1}, {R3, 0, 5}, {B3, 3, 1}, {PB, 0, 5}}};
    case 30:
      return {
          true, false, 2, 6, {0, 0, 0}, 24, {{R0, 0, 6}, {G3, 4, 1}, {B3, 0, 1}, {B3, 1, 1}, {B2, 4, 1}, {G0, 0, 6},
                                             {G2, 5, 1}, {B2, 5, 1}, {B3, 2, 1}, {G2, 4, 1}, {B0, 0, 6}, {G3, 5, 1},
                                             {B3, 3, 1}, {B3, 5, 1}, {B3, 4, 1}, {R1, 0, 6}, {G2, 0, 4}, {G1, 0, 6},
                                             {G3, 0, 4}, {B1, 0, 6}, {B2, 0, 4}, {R2, 0, 6}, {R3, 0, 6}, {PB, 0, 5}}};
    case 3:
      return {true,
              false,
              1,
              10,
              {0, 0, 0},
              6,
              {{R0, 0, 10}, {G0, 0, 10}, {B0, 0, 10}, {R1, 0, 10}, {G1, 0, 10}, {B1, 0, 10}}};
    case 7:
      return {true,
              true,
              1,
              11,
              {9, 9, 9},
              9,
              {{R0, 0, 10},
               {G0, 0, 10},
               {B0, 0, 10},
               {R1, 0, 9},
               {R0, 10, 1},
               {G1, 0, 9},
               {G0, 10, 1},
               {B1, 0, 9},
               {B0, 10, 1}}};
    case 11:
      return {true,
              true,
              1,
              12,
              {8, 8, 8},
              9,
              {{R0, 0, 10},
               {G0, 0, 10},
               {B0, 0, 10},
               {R1, 0, 8},
               {R0, 10, 2, true},
               {G1, 0, 8},
               {G0, 10, 2, true},
               {B1, 0, 8},
               {B0, 10, 2, true}}};
    case 15:
      return {true,
              true,
              1,
              16,
              {4, 4, 4},
              9,
              {{R0, 0, 10},
               {G0, 0, 10},
               {B0, 0, 10},
               {R1, 0, 4},
               {R0, 10, 6, true},
               {G1, 0, 4},
               {G0, 10, 6, true},
               {B1, 0, 4},
               {B0, 10, 6, true}}};
    default: return {false, false, 0, 0, {0, 0, 0}, 0, {}};
  }
}

struct Bc6ModeTable {
  Bc6Mode modes[32];
  constexpr Bc6ModeTable() : modes{} {
    for (uint32_t m = 0; m < 32; ++m) modes[m] = bc6Mode(m);
  }
};
constexpr Bc6ModeTable kBc6Modes;

int32_t signExtend(uint32_t v, uint32_t bits) {
  uint32_t sign = 1u << (bits - 1);
  return int32_t((v & ((sign << 1) - 1)) ^ sign) - int32_t(sign);
}

// The unquantization of endpoints (the spec's pseudocode for unsigned and signed formats).
int32_t unquantize(int32_t x, uint32_t bits, bool isSigned) {
  if (!isSigned) {
    if (bits >= 15) return x;
    if (x == 0) return 0;
    if (x == int32_t((1u << bits) - 1)) return 0xFFFF;
    return ((x << 15) + 0x4000) >> (bits - 1);
  }
  if (bits >= 16) return x;
  bool negative = x < 0;
  if (negative) x = -x;
  int32_t unq;
  if (x == 0)
    unq = 0;
  else if (x >= int32_t((1u << (bits - 1)) - 1))
    unq = 0x7FFF;
  else
    unq = ((x << 15) + 0x4000) >> (bits - 1);
  return negative ? -unq : unq;
}

float halfToFloat(uint32_t h) {
  uint32_t sign = (h >> 15) & 1, exponent = (h >> 10) & 31, mantissa = h & 1023;
  float magnitude;
  if (exponent == 0)
    magnitude = float(mantissa) * (1.0f / 16777216.0f);  // 2^-24
  else if (exponent == 31)
    magnitude = mantissa ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  else {
    uint32_t bits = ((exponent + 112) << 23) | (mantissa << 13);
    std::memcpy(&magnitude, &bits, sizeof magnitude);
  }
  return sign ? -magnitude : magnitude;
}

void decodeBc6h(const uint8_t* block, bool isSigned, float out[16][4]) {
  Bits in(block, 16);
  uint32_t modeNumber = in.at(0, 2) < 2 ? in.at(0, 2) : in.at(0, 5);
  const Bc6Mode& m = kBc6Modes.modes[modeNumber];
  if (!m.valid) {  // reserved: (0, 0, 0, 1)
    for (int i = 0; i < 16; ++i) setTexel(out[i], 0, 0, 0, 1);
    return;
  }
  in.seek(modeNumber < 2 ? 2 : 5);
  uint32_t field[13] = {};
  for (uint32_t s = 0; s < m.segmentCount; ++s) {
    const Bc6Segment& seg = m.segments[s];
    uint32_t v = in.read(seg.count);
    if (seg.reversed) {
      uint32_t r = 0;
      for (uint32_t b = 0; b < seg.count; ++b) r |= ((v >> b) & 1) << (seg.count - 1 - b);
      v = r;
    }
    field[seg.field] |= v << seg.shift;
  }
  uint32_t endpoints = 2 * m.regions;
  uint32_t mask = (1u << m.endpointBits) - 1;
  int32_t ep[4][3];
  for (uint32_t ch = 0; ch < 3; ++ch) {
    // E0 is sign-extended for signed formats; the others also when they are deltas (at the delta width).
    ep[0][ch] = isSigned ? signExtend(field[ch], m.endpointBits) : int32_t(field[ch]);
    for (uint32_t e = 1; e < endpoints; ++e) {
      uint32_t raw = field[3 * e + ch];
      if (m.transformed) {
        // Transformed endpoints: E0 plus the delta, wrapped at the endpoint bits.
        uint32_t v = (uint32_t(ep[0][ch]) + uint32_t(signExtend(raw, m.deltaBits[ch]))) & mask;
        ep[e][ch] = isSigned ? signExtend(v, m.endpointBits) : int32_t(v);
      } else {
        ep[e][ch] = isSigned ? signExtend(raw, m.endpointBits) : int32_t(raw);
      }
    }
  }
  for (uint32_t e = 0; e < endpoints; ++e)
    for (uint32_t ch = 0; ch < 3; ++ch) ep[e][ch] = unquantize(ep[e][ch], m.endpointBits, isSigned);
  uint32_t partition = m.regions == 2 ? field[PB] : 0;
  uint32_t indexBits = m.regions == 2 ? 3 : 4;
  in.seek(m.regions == 2 ? 82 : 65);
  uint8_t index[16];
  readIndices(in, m.regions, partition, indexBits, index);
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t s = subsetOf(m.regions, partition, i);
    uint32_t w = weight(indexBits, index[i]);
    float c[3];
    for (uint32_t ch = 0; ch < 3; ++ch) {
      int32_t v = interpolate(ep[2 * s][ch], ep[2 * s + 1][ch], w);
      // The final unquantization into half-float bit patterns.
      uint32_t h = !isSigned ? uint32_t(v * 31) >> 6
                   : v < 0   ? (uint32_t(-v * 31) >> 5) | 0x8000
                             : uint32_t(v * 31) >> 5;
      c[ch] = halfToFloat(h);
    }
    setTexel(out[i], c[0], c[1], c[2], 1.0f);
  }
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
    case Kind::BC6H_SFLOAT: decodeBc6h(block, kind == Kind::BC6H_SFLOAT, out); return;
    case Kind::BC7: decodeBc7(block, out); return;
  }
}

}  // namespace vkrt::bc
