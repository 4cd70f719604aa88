// The BC block decoders of runtime/bc_decode.hpp against expectations computed here from the Khronos Data Format
// Specification 1.3 (S3TC, RGTC and BPTC sections): blocks are built field by field with a bit writer, as the spec
// lays out each format and BPTC mode, and every texel's expected value is derived from those fields with the spec's
// formulas written out here. The BPTC tables the expectations need (partitions, anchors, BC6H field layouts) are
// transcribed in a layout of their own, as text close to the spec's, not taken from the decoder.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "runtime/bc_decode.hpp"

namespace vkrt::bc {
namespace {

// Writes fields from bit 0 of byte 0 up (the blocks' little-endian bit order).
class BitWriter {
 public:
  void put(uint64_t value, uint32_t n) {
    for (uint32_t i = 0; i < n; ++i, ++pos_)
      if (pos_ < 128 && ((value >> i) & 1)) bytes_[pos_ / 8] |= uint8_t(1u << (pos_ % 8));
  }
  uint32_t pos() const { return pos_; }
  const uint8_t* data() const { return bytes_; }

 private:
  uint8_t bytes_[16] = {};
  uint32_t pos_ = 0;
};

// A small deterministic generator (xorshift64*).
struct Rng {
  uint64_t s;
  uint32_t bits(uint32_t n) {
    s ^= s >> 12;
    s ^= s << 25;
    s ^= s >> 27;
    uint64_t v = (s * 0x2545F4914F6CDD1Dull) >> 32;
    return n >= 32 ? uint32_t(v) : uint32_t(v) & ((1u << n) - 1);
  }
};

struct Texels {
  float t[16][4];
};

// Decodes from a heap copy of exactly blockBytes(kind) bytes, so that AddressSanitizer reports any read past it.
Texels decode(Kind kind, const uint8_t* block) {
  std::vector<uint8_t> copy(block, block + blockBytes(kind));
  Texels out;
  for (auto& t : out.t)
    for (float& c : t) c = -12345.0f;
  decodeBlock(kind, copy.data(), out.t);
  return out;
}

void expectTexel(const float got[4], double r, double g, double b, double a, double tolerance,
                 const std::string& what) {
  EXPECT_NEAR(got[0], r, tolerance) << what << " R";
  EXPECT_NEAR(got[1], g, tolerance) << what << " G";
  EXPECT_NEAR(got[2], b, tolerance) << what << " B";
  EXPECT_NEAR(got[3], a, tolerance) << what << " A";
}

constexpr double kTol = 1e-6;

// ---- S3TC ----

uint16_t rgb565(uint32_t r, uint32_t g, uint32_t b) { return uint16_t(r << 11 | g << 5 | b); }

struct Rgb {
  double r, g, b;
};
Rgb unpack565(uint16_t c) { return {(c >> 11) / 31.0, ((c >> 5) & 63) / 63.0, (c & 31) / 31.0}; }
Rgb mix(Rgb a, double wa, Rgb b, double wb, double d) {
  return {(wa * a.r + wb * b.r) / d, (wa * a.g + wb * b.g) / d, (wa * a.b + wb * b.b) / d};
}

// color0, color1 (little-endian), then 2-bit codes from texel 0 up.
void putBc1(uint8_t* b, uint16_t c0, uint16_t c1, const uint32_t code[16]) {
  b[0] = uint8_t(c0), b[1] = uint8_t(c0 >> 8), b[2] = uint8_t(c1), b[3] = uint8_t(c1 >> 8);
  uint32_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= code[i] << (2 * i);
  for (int i = 0; i < 4; ++i) b[4 + i] = uint8_t(bits >> (8 * i));
}

// "Block decoding for BC1": the colour of a code, in 4-colour mode (color0 > color1) or 3-colour + black mode.
Rgb bc1Color(uint16_t c0, uint16_t c1, uint32_t code, bool fourColors) {
  Rgb e0 = unpack565(c0), e1 = unpack565(c1);
  if (code == 0) return e0;
  if (code == 1) return e1;
  if (fourColors) return code == 2 ? mix(e0, 2, e1, 1, 3) : mix(e0, 1, e1, 2, 3);
  return code == 2 ? mix(e0, 1, e1, 1, 2) : Rgb{0, 0, 0};
}

void checkBc1(uint16_t c0, uint16_t c1) {
  uint32_t code[16];
  for (int i = 0; i < 16; ++i) code[i] = (i * 3 + i / 4) % 4;
  uint8_t b[8];
  putBc1(b, c0, c1, code);
  bool fourColors = c0 > c1;
  Texels rgb = decode(Kind::BC1_RGB, b), rgba = decode(Kind::BC1_RGBA, b);
  for (int i = 0; i < 16; ++i) {
    Rgb e = bc1Color(c0, c1, code[i], fourColors);
    std::string what = "texel " + std::to_string(i) + " code " + std::to_string(code[i]);
    // BC1 with no alpha: opaque, code 3 of the 3-colour mode is opaque black.
    expectTexel(rgb.t[i], e.r, e.g, e.b, 1.0, kTol, "BC1_RGB " + what);
    // BC1 with alpha: code 3 of the 3-colour mode is transparent black.
    double a = !fourColors && code[i] == 3 ? 0.0 : 1.0;
    expectTexel(rgba.t[i], e.r, e.g, e.b, a, kTol, "BC1_RGBA " + what);
  }
}

// The spec's example endpoints (29/31, 60/63, 1/31) and (20/31, 2/63, 30/31), in both orders.
TEST(BcDecode, Bc1FourColorMode) { checkBc1(rgb565(29, 60, 1), rgb565(20, 2, 30)); }
TEST(BcDecode, Bc1ThreeColorModePunchThrough) { checkBc1(rgb565(20, 2, 30), rgb565(29, 60, 1)); }
// Equal endpoints are color0 <= color1: the 3-colour mode.
TEST(BcDecode, Bc1EqualEndpointsAreThreeColorMode) { checkBc1(rgb565(7, 40, 9), rgb565(7, 40, 9)); }
// The comparison is of the 16-bit integers (red in the high bits), not per channel.
TEST(BcDecode, Bc1ComparesWholeIntegers) {
  checkBc1(rgb565(16, 0, 0), rgb565(15, 63, 31));
  checkBc1(rgb565(15, 63, 31), rgb565(16, 0, 0));
}

// BC2 and BC3 colour: always the 4-colour encoding, whatever the order of the endpoints.
void expectForcedFourColors(const Texels& got, uint16_t c0, uint16_t c1, const uint32_t code[16], const char* kind) {
  for (int i = 0; i < 16; ++i) {
    Rgb e = bc1Color(c0, c1, code[i], true);
    EXPECT_NEAR(got.t[i][0], e.r, kTol) << kind << " texel " << i;
    EXPECT_NEAR(got.t[i][1], e.g, kTol) << kind << " texel " << i;
    EXPECT_NEAR(got.t[i][2], e.b, kTol) << kind << " texel " << i;
  }
}

TEST(BcDecode, Bc2ExplicitAlphaNibbles) {
  uint8_t b[16] = {};
  uint32_t alpha[16], code[16];
  for (int i = 0; i < 16; ++i) alpha[i] = (i * 7 + 3) % 16, code[i] = (i + i / 4) % 4;
  uint64_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint64_t(alpha[i]) << (4 * i);
  for (int i = 0; i < 8; ++i) b[i] = uint8_t(bits >> (8 * i));
  uint16_t c0 = rgb565(3, 10, 20), c1 = rgb565(30, 50, 5);  // color0 < color1
  putBc1(b + 8, c0, c1, code);
  Texels got = decode(Kind::BC2, b);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(got.t[i][3], alpha[i] / 15.0, kTol) << "texel " << i;
  expectForcedFourColors(got, c0, c1, code, "BC2");
}

// RGTC: 2 endpoint bytes, then 16 3-bit codes.
void putRgtc(uint8_t* b, uint8_t e0, uint8_t e1, const uint32_t code[16]) {
  b[0] = e0, b[1] = e1;
  uint64_t bits = 0;
  for (int i = 0; i < 16; ++i) bits |= uint64_t(code[i]) << (3 * i);
  for (int i = 0; i < 6; ++i) b[2 + i] = uint8_t(bits >> (8 * i));
}

// "Block decoding for BC4" (and BC3's alpha): E0, E1 as decoded, 8 values if the stored red0 > red1.
double rgtcValue(double e0, double e1, bool eightValues, uint32_t code, double lo) {
  if (code == 0) return e0;
  if (code == 1) return e1;
  if (eightValues) return ((8 - code) * e0 + (code - 1) * e1) / 7.0;
  if (code <= 5) return ((6 - code) * e0 + (code - 1) * e1) / 5.0;
  return code == 6 ? lo : 1.0;
}

double snorm8(uint8_t v) {
  int s = int8_t(v);
  return s == -128 ? -1.0 : s / 127.0;
}

void codes8(uint32_t code[16], int salt) {
  for (int i = 0; i < 16; ++i) code[i] = (i * 5 + salt + i / 8) % 8;
}

TEST(BcDecode, Bc3InterpolatedAlphaBothModes) {
  for (auto [a0, a1] : {std::pair<int, int>{200, 40}, {40, 200}, {90, 90}, {255, 0}}) {
    uint8_t b[16] = {};
    uint32_t alphaCode[16], code[16];
    codes8(alphaCode, a0);
    for (int i = 0; i < 16; ++i) code[i] = 3 - i % 4;
    putRgtc(b, uint8_t(a0), uint8_t(a1), alphaCode);
    uint16_t c0 = rgb565(1, 2, 3), c1 = rgb565(31, 63, 31);  // color0 < color1
    putBc1(b + 8, c0, c1, code);
    Texels got = decode(Kind::BC3, b);
    for (int i = 0; i < 16; ++i)
      EXPECT_NEAR(got.t[i][3], rgtcValue(a0 / 255.0, a1 / 255.0, a0 > a1, alphaCode[i], 0.0), kTol)
          << "alpha0 " << a0 << " alpha1 " << a1 << " texel " << i << " code " << alphaCode[i];
    expectForcedFourColors(got, c0, c1, code, "BC3");
  }
}

TEST(BcDecode, Bc4UnsignedBothModes) {
  for (auto [r0, r1] : {std::pair<int, int>{250, 10}, {10, 250}, {0, 255}, {128, 128}}) {
    uint8_t b[8];
    uint32_t code[16];
    codes8(code, r1);
    putRgtc(b, uint8_t(r0), uint8_t(r1), code);
    Texels got = decode(Kind::BC4_UNORM, b);
    for (int i = 0; i < 16; ++i)
      expectTexel(got.t[i], rgtcValue(r0 / 255.0, r1 / 255.0, r0 > r1, code[i], 0.0), 0, 0, 1, kTol,
                  "red0 " + std::to_string(r0) + " red1 " + std::to_string(r1) + " texel " + std::to_string(i));
  }
}

// Signed: the comparison is of the two's complement values; -128 decodes like -127, to -1.0; RED_min is -1.0.
TEST(BcDecode, Bc4SignedBothModesAndExtremes) {
  for (auto [r0, r1] : {std::pair<int, int>{127, -128}, {-128, 127}, {-100, 50}, {60, -3}, {5, 5}, {-1, 0}}) {
    uint8_t b[8];
    uint32_t code[16];
    codes8(code, r0 & 7);
    putRgtc(b, uint8_t(r0), uint8_t(r1), code);
    Texels got = decode(Kind::BC4_SNORM, b);
    for (int i = 0; i < 16; ++i)
      expectTexel(got.t[i], rgtcValue(snorm8(uint8_t(r0)), snorm8(uint8_t(r1)), r0 > r1, code[i], -1.0), 0, 0, 1, kTol,
                  "red0 " + std::to_string(r0) + " red1 " + std::to_string(r1) + " texel " + std::to_string(i));
  }
  // The endpoints themselves: 127 -> 1.0 and -128 -> -1.0 exactly.
  uint8_t b[8];
  uint32_t code[16];
  for (int i = 0; i < 16; ++i) code[i] = i % 2;
  putRgtc(b, 127, 0x80, code);
  Texels got = decode(Kind::BC4_SNORM, b);
  EXPECT_EQ(got.t[0][0], 1.0f);
  EXPECT_EQ(got.t[1][0], -1.0f);
}

TEST(BcDecode, Bc5TwoChannels) {
  for (Kind kind : {Kind::BC5_UNORM, Kind::BC5_SNORM}) {
    bool isSigned = kind == Kind::BC5_SNORM;
    uint8_t b[16];
    uint32_t red[16], green[16];
    codes8(red, 1);
    codes8(green, 6);
    // Red in the 8-value mode, green in the 6-value mode (for both signednesses).
    uint8_t r0 = isSigned ? 0x70 : 0xF0, r1 = isSigned ? 0x90 : 0x10, g0 = isSigned ? 0x85 : 0x20,
            g1 = isSigned ? 0x60 : 0xE0;
    putRgtc(b, r0, r1, red);
    putRgtc(b + 8, g0, g1, green);
    Texels got = decode(kind, b);
    auto value = [&](uint8_t e0, uint8_t e1, uint32_t c) {
      if (isSigned) return rgtcValue(snorm8(e0), snorm8(e1), int8_t(e0) > int8_t(e1), c, -1.0);
      return rgtcValue(e0 / 255.0, e1 / 255.0, e0 > e1, c, 0.0);
    };
    for (int i = 0; i < 16; ++i)
      expectTexel(got.t[i], value(r0, r1, red[i]), value(g0, g1, green[i]), 0, 1, kTol,
                  std::string(isSigned ? "SNORM" : "UNORM") + " texel " + std::to_string(i));
  }
}

// ---- BPTC tables, transcribed from the spec's tables as text ----

// "Partition table for 2-subset BPTC" and "... 3-subset BPTC": texel x + 4 * y's subset, one digit each.
const char* const kP2[64] = {
    "0011001100110011", "0001000100010001", "0111011101110111", "0001001100110111", "0000000100010011",
    "0011011101111111", "0001001101111111", "0000000100110111", "0000000000010011", "0011011111111111",
    "0000000101111111", "0000000000010111", "0001011111111111", "0000000011111111", "0000111111111111",
    "0000000000001111", "0000100011101111", "0111000100000000", "0000000010001110", "0111001100010000",
    "0011000100000000", "0000100011001110", "0000000010001100", "0111001100110001", "0011000100010000",
    "0000100010001100", "0110011001100110", "0011011001101100", "0001011111101000", "0000111111110000",
    "0111000110001110", "0011100110011100", "0101010101010101", "0000111100001111", "0101101001011010",
    "0011001111001100", "0011110000111100", "0101010110101010", "0110100101101001", "0101101010100101",
    "0111001111001110", "0001001111001000", "0011001001001100", "0011101111011100", "0110100110010110",
    "0011110011000011", "0110011010011001", "0000011001100000", "0100111001000000", "0010011100100000",
    "0000001001110010", "0000010011100100", "0110110010010011", "0011011011001001", "0110001110011100",
    "0011100111000110", "0110110011001001", "0110001100111001", "0111111010000001", "0001100011100111",
    "0000111100110011", "0011001111110000", "0010001011101110", "0100010001110111",
};
const char* const kP3[64] = {
    "0011001102212222", "0001001122112221", "0000200122112211", "0222002200110111", "0000000011221122",
    "0011001100220022", "0022002211111111", "0011001122112211", "0000000011112222", "0000111111112222",
    "0000111122222222", "0012001200120012", "0112011201120112", "0122012201220122", "0011011211221222",
    "0011200122002220", "0001001101121122", "0111001120012200", "0000112211221122", "0022002200221111",
    "0111011102220222", "0001000122212221", "0000001101220122", "0000110022102210", "0122012200110000",
    "0012001211222222", "0110122112210110", "0000011012211221", "0022110211020022", "0110011020022222",
    "0011012201220011", "0000200022112221", "0000000211221222", "0222002200120011", "0011001200220222",
    "0120012001200120", "0000111122220000", "0120120120120120", "0120201212010120", "0011220011220011",
    "0011112222000011", "0101010122222222", "0000000021212121", "0022112200221122", "0022001100220011",
    "0220122102201221", "0101222222220101", "0000212121212121", "0101010101012222", "0222011102220111",
    "0002111200021112", "0000211221122112", "0222011101110222", "0002111211120002", "0110011001102222",
    "0000000021122112", "0110011022222222", "0022001100110022", "0022112211220022", "0000000000002112",
    "0002000100020001", "0222122202221222", "0101222222222222", "0111201122012220",
};
// The anchor index tables, one hex digit per partition: second subset of 2, second and third subsets of 3.
const char kA2[] = "fffffffffffffffff282288f28228822ff6828ff28222ff66268ff22fffff22f";
const char kA32[] = "33ff83ff88666533338f336a588685ff8f356a8ff3f5ffff3f55585a5a8dfc33";
const char kA33[] = "f883ff38fffffff8f8f3f8f83f6affa8f3faa89a6f8f3668f3ffffffffff3ff8";

uint32_t hexDigit(char c) { return c <= '9' ? uint32_t(c - '0') : uint32_t(c - 'a' + 10); }

uint32_t subsetOfTexel(uint32_t subsets, uint32_t partition, uint32_t texel) {
  if (subsets == 1) return 0;
  return uint32_t((subsets == 2 ? kP2 : kP3)[partition][texel] - '0');
}

// Anchor indices: texel 0 for subset 0, then the tables.
bool anchorTexel(uint32_t subsets, uint32_t partition, uint32_t texel) {
  if (texel == 0) return true;
  if (subsets == 2) return texel == hexDigit(kA2[partition]);
  if (subsets == 3) return texel == hexDigit(kA32[partition]) || texel == hexDigit(kA33[partition]);
  return false;
}

// The tables hang together: each anchor lies in its subset, and partition 0 of each starts with subset 0.
TEST(BcDecode, BptcTestTablesAreConsistent) {
  for (uint32_t p = 0; p < 64; ++p) {
    EXPECT_EQ(kP2[p][hexDigit(kA2[p])], '1') << p;
    EXPECT_EQ(kP3[p][hexDigit(kA32[p])], '1') << p;
    EXPECT_EQ(kP3[p][hexDigit(kA33[p])], '2') << p;
    EXPECT_EQ(kP2[p][0], '0');
    EXPECT_EQ(kP3[p][0], '0');
  }
}

// The weights of "BPTC interpolation factors", by the spec's formulas (not its table).
uint32_t bptcWeight(uint32_t bits, uint32_t index) {
  if (bits == 2) return index * 21 + (index >> 1);
  if (bits == 3) return index * 9 + (index >> 2);
  return (index << 2) + (index >> 2) + ((index >> 1) & 1);
}

TEST(BcDecode, BptcWeightFormulasMatchTheTable) {
  const uint32_t w4[16] = {0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64};
  const uint32_t w3[8] = {0, 9, 18, 27, 37, 46, 55, 64};
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(bptcWeight(4, i), w4[i]);
  for (uint32_t i = 0; i < 8; ++i) EXPECT_EQ(bptcWeight(3, i), w3[i]);
  EXPECT_EQ(bptcWeight(2, 1), 21u);
  EXPECT_EQ(bptcWeight(2, 2), 43u);
}

int32_t bptcInterpolate(int32_t e0, int32_t e1, uint32_t w) {
  return ((64 - int32_t(w)) * e0 + int32_t(w) * e1 + 32) >> 6;
}

// ---- BC7 ----

// "Mode-dependent BPTC parameters".
struct Bc7Params {
  uint32_t ns, pb, rb, isb, cb, ab, epb, spb, ib, ib2;
};
const Bc7Params kBc7Params[8] = {
    {3, 4, 0, 0, 4, 0, 1, 0, 3, 0}, {2, 6, 0, 0, 6, 0, 0, 1, 3, 0}, {3, 6, 0, 0, 5, 0, 0, 0, 2, 0},
    {2, 6, 0, 0, 7, 0, 1, 0, 2, 0}, {1, 0, 2, 1, 5, 6, 0, 0, 2, 3}, {1, 0, 2, 0, 7, 8, 0, 0, 2, 2},
    {1, 0, 0, 0, 7, 7, 1, 0, 4, 0}, {2, 6, 0, 0, 5, 5, 1, 0, 2, 0},
};

struct Bc7Fields {
  uint32_t mode = 0, partition = 0, rotation = 0, indexSelection = 0;
  uint32_t color[6][3] = {}, alpha[6] = {};
  uint32_t pbit[6] = {};  // per endpoint (EPB), or per subset (SPB)
  uint32_t index[16] = {}, index2[16] = {};
};

// Random fields for a mode; anchor indices get their top bit zero (the bit the block does not store).
Bc7Fields randomBc7(Rng& rng, uint32_t mode) {
  const Bc7Params& m = kBc7Params[mode];
  Bc7Fields f;
  f.mode = mode;
  f.partition = rng.bits(m.pb);
  f.rotation = rng.bits(m.rb);
  f.indexSelection = rng.bits(m.isb);
  for (auto& c : f.color)
    for (uint32_t& v : c) v = rng.bits(m.cb);
  for (uint32_t& a : f.alpha) a = rng.bits(m.ab);
  for (uint32_t& p : f.pbit) p = rng.bits(1);
  for (uint32_t i = 0; i < 16; ++i) {
    f.index[i] = rng.bits(m.ib - (anchorTexel(m.ns, f.partition, i) ? 1 : 0));
    if (m.ib2) f.index2[i] = rng.bits(m.ib2 - (i == 0 ? 1 : 0));
  }
  return f;
}

// The block, in "Bit layout for BC7 modes" order: mode, partition, rotation, index selection, colour (R of every
// endpoint, then G, then B), alpha, per-endpoint P-bits, shared P-bits, primary indices, secondary indices.
void encodeBc7(const Bc7Fields& f, uint8_t out[16]) {
  const Bc7Params& m = kBc7Params[f.mode];
  BitWriter w;
  w.put(1u << f.mode, f.mode + 1);
  w.put(f.partition, m.pb);
  w.put(f.rotation, m.rb);
  w.put(f.indexSelection, m.isb);
  for (uint32_t ch = 0; ch < 3; ++ch)
    for (uint32_t e = 0; e < 2 * m.ns; ++e) w.put(f.color[e][ch], m.cb);
  for (uint32_t e = 0; e < 2 * m.ns && m.ab; ++e) w.put(f.alpha[e], m.ab);
  for (uint32_t e = 0; e < 2 * m.ns && m.epb; ++e) w.put(f.pbit[e], 1);
  for (uint32_t s = 0; s < m.ns && m.spb; ++s) w.put(f.pbit[s], 1);
  for (uint32_t i = 0; i < 16; ++i) w.put(f.index[i], m.ib - (anchorTexel(m.ns, f.partition, i) ? 1 : 0));
  for (uint32_t i = 0; i < 16 && m.ib2; ++i) w.put(f.index2[i], m.ib2 - (i == 0 ? 1 : 0));
  EXPECT_EQ(w.pos(), 128u) << "mode " << f.mode;
  std::memcpy(out, w.data(), 16);
}

// An n-bit value as the top bits of a byte, its own top bits repeated below it.
uint32_t replicateTo8(uint32_t v, uint32_t n) {
  uint32_t r = 0;
  for (uint32_t k = 0; k < 8; ++k) r |= ((v >> (n - 1 - k % n)) & 1) << (7 - k);
  return r;
}

// The expected RGBA8 of every texel.
void expectBc7(const Bc7Fields& f, uint32_t rgba[16][4]) {
  const Bc7Params& m = kBc7Params[f.mode];
  uint32_t ep[6][4];
  for (uint32_t e = 0; e < 2 * m.ns; ++e) {
    uint32_t p = m.epb ? f.pbit[e] : m.spb ? f.pbit[e / 2] : 0;
    bool hasP = m.epb || m.spb;
    for (uint32_t ch = 0; ch < 4; ++ch) {
      uint32_t bits = ch < 3 ? m.cb : m.ab, v = ch < 3 ? f.color[e][ch] : f.alpha[e];
      if (bits == 0) {
        ep[e][ch] = 255;  // no alpha bits: opaque
        continue;
      }
      if (hasP) v = v << 1 | p, ++bits;
      ep[e][ch] = replicateTo8(v, bits);
    }
  }
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t s = subsetOfTexel(m.ns, f.partition, i);
    bool colorFrom2 = m.isb && f.indexSelection == 1;
    bool alphaFrom2 = m.ib2 && !(m.isb && f.indexSelection == 1);
    uint32_t wc = colorFrom2 ? bptcWeight(m.ib2, f.index2[i]) : bptcWeight(m.ib, f.index[i]);
    uint32_t wa = alphaFrom2 ? bptcWeight(m.ib2, f.index2[i]) : bptcWeight(m.ib, f.index[i]);
    for (uint32_t ch = 0; ch < 4; ++ch)
      rgba[i][ch] = uint32_t(bptcInterpolate(int32_t(ep[2 * s][ch]), int32_t(ep[2 * s + 1][ch]), ch < 3 ? wc : wa));
    if (f.rotation) std::swap(rgba[i][3], rgba[i][f.rotation - 1]);
  }
}

void checkBc7(const Bc7Fields& f) {
  uint8_t block[16];
  encodeBc7(f, block);
  uint32_t want[16][4];
  expectBc7(f, want);
  Texels got = decode(Kind::BC7, block);
  for (int i = 0; i < 16; ++i)
    for (int ch = 0; ch < 4; ++ch)
      ASSERT_NEAR(got.t[i][ch], want[i][ch] / 255.0, kTol)
          << "mode " << f.mode << " partition " << f.partition << " rotation " << f.rotation << " index selection "
          << f.indexSelection << " texel " << i << " channel " << ch;
}

TEST(BcDecode, Bc7EveryModeRandomFields) {
  Rng rng{0x1234567};
  for (uint32_t mode = 0; mode < 8; ++mode)
    for (int n = 0; n < 200; ++n) checkBc7(randomBc7(rng, mode));
}

// Every partition of the 2- and 3-subset modes, whose anchors move the following indices' bit offsets.
TEST(BcDecode, Bc7EveryPartitionAndAnchor) {
  Rng rng{99};
  for (uint32_t mode : {0u, 1u, 2u, 3u, 7u})
    for (uint32_t p = 0; p < (1u << kBc7Params[mode].pb); ++p)
      for (int n = 0; n < 4; ++n) {
        Bc7Fields f = randomBc7(rng, mode);
        f.partition = p;
        for (uint32_t i = 0; i < 16; ++i)  // indices redrawn for this partition's anchors
          f.index[i] = rng.bits(kBc7Params[mode].ib - (anchorTexel(kBc7Params[mode].ns, p, i) ? 1 : 0));
        checkBc7(f);
      }
}

// Modes 4 and 5: each rotation, and mode 4's index selection, on fixed endpoints whose channels differ.
TEST(BcDecode, Bc7RotationAndIndexSelection) {
  Rng rng{7};
  for (uint32_t mode : {4u, 5u})
    for (uint32_t rotation = 0; rotation < 4; ++rotation)
      for (uint32_t selection = 0; selection < (mode == 4 ? 2u : 1u); ++selection) {
        Bc7Fields f = randomBc7(rng, mode);
        f.rotation = rotation;
        f.indexSelection = selection;
        checkBc7(f);
      }
  // One by hand: mode 4, index selection 1 (colour from the 3-bit indices), rotation 1 (swap A and R); endpoint 0
  // = (0, 0, 0, 0), endpoint 1 = (31, 31, 31, 63) -> 255; texel 15 has 2-bit index 3 and 3-bit index 4.
  Bc7Fields f;
  f.mode = 4;
  f.rotation = 1;
  f.indexSelection = 1;
  f.color[1][0] = f.color[1][1] = f.color[1][2] = 31;
  f.alpha[1] = 63;
  f.index[15] = 3;
  f.index2[15] = 4;
  uint8_t block[16];
  encodeBc7(f, block);
  Texels got = decode(Kind::BC7, block);
  // Colour weight 37 -> (37 * 255 + 32) >> 6 = 147; alpha weight 64 -> 255; then R and A swap.
  EXPECT_NEAR(got.t[15][0], 255 / 255.0, kTol);
  EXPECT_NEAR(got.t[15][1], 147 / 255.0, kTol);
  EXPECT_NEAR(got.t[15][2], 147 / 255.0, kTol);
  EXPECT_NEAR(got.t[15][3], 147 / 255.0, kTol);
  expectTexel(got.t[0], 0, 0, 0, 0, kTol, "texel 0");
}

// P-bits: mode 6's per-endpoint bits and mode 1's shared ones land below the stored bits, alpha included.
TEST(BcDecode, Bc7PBits) {
  Bc7Fields f;
  f.mode = 6;
  for (int ch = 0; ch < 3; ++ch) f.color[0][ch] = f.color[1][ch] = 0x40;
  f.alpha[0] = f.alpha[1] = 0x7F;
  f.pbit[0] = 1;
  f.pbit[1] = 0;
  f.index[1] = 15;  // texel 1 at endpoint 1
  uint8_t block[16];
  encodeBc7(f, block);
  Texels got = decode(Kind::BC7, block);
  expectTexel(got.t[0], 0x81 / 255.0, 0x81 / 255.0, 0x81 / 255.0, 1.0, kTol, "mode 6 endpoint 0 (P-bit 1)");
  expectTexel(got.t[1], 0x80 / 255.0, 0x80 / 255.0, 0x80 / 255.0, 0xFE / 255.0, kTol, "mode 6 endpoint 1 (P-bit 0)");
  Rng rng{3};
  for (int n = 0; n < 50; ++n) checkBc7(randomBc7(rng, 1));
  for (int n = 0; n < 50; ++n) checkBc7(randomBc7(rng, 3));
}

// A low byte of 0 has no mode bit: reserved; decoded as 0 in all channels of all texels.
TEST(BcDecode, Bc7NoModeBitIsTransparentBlack) {
  Rng rng{5};
  for (int n = 0; n < 8; ++n) {
    uint8_t block[16];
    for (uint8_t& b : block) b = uint8_t(rng.bits(8));
    block[0] = 0;
    if (n == 0) std::memset(block, 0, 16);
    Texels got = decode(Kind::BC7, block);
    for (int i = 0; i < 16; ++i) expectTexel(got.t[i], 0, 0, 0, 0, 0, "texel " + std::to_string(i));
  }
}

// ---- BC6H ----

// "Block descriptions for BC6H block modes", after the mode bits, in the spec's notation: Xn^a:b moves bits from
// the block into bits b, then towards a, of field Xn (R0..B3 or PB); Xn^a is one bit.
struct Bc6Params {
  uint32_t mode;
  bool transformed;
  uint32_t regions, epb, delta[3];
  const char* layout;
};
const Bc6Params kBc6Params[14] = {
    {0,
     true,
     2,
     10,
     {5, 5, 5},
     "G2^4 B2^4 B3^4 R0^9:0 G0^9:0 B0^9:0 R1^4:0 G3^4 G2^3:0 G1^4:0 B3^0 G3^3:0 B1^4:0 B3^1 B2^3:0 R2^4:0 B3^2 "
     "R3^4:0 B3^3 PB^4:0"},
    {1,
     true,
     2,
     7,
     {6, 6, 6},
     "G2^5 G3^4 G3^5 R0^6:0 B3^0 B3^1 B2^4 G0^6:0 B2^5 B3^2 G2^4 B0^6:0 B3^3 B3^5 B3^4 R1^5:0 G2^3:0 G1^5:0 G3^3:0 "
     "B1^5:0 B2^3:0 R2^5:0 R3^5:0 PB^4:0"},
    {2,
     true,
     2,
     11,
     {5, 4, 4},
     "R0^9:0 G0^9:0 B0^9:0 R1^4:0 R0^10 G2^3:0 G1^3:0 G0^10 B3^0 G3^3:0 B1^3:0 B0^10 B3^1 B2^3:0 R2^4:0 B3^2 R3^4:0 "
     "B3^3 PB^4:0"},
    {6,
     true,
     2,
     11,
     {4, 5, 4},
     "R0^9:0 G0^9:0 B0^9:0 R1^3:0 R0^10 G3^4 G2^3:0 G1^4:0 G0^10 G3^3:0 B1^3:0 B0^10 B3^1 B2^3:0 R2^3:0 B3^0 B3^2 "
     "R3^3:0 G2^4 B3^3 PB^4:0"},
    {10,
     true,
     2,
     11,
     {4, 4, 5},
     "R0^9:0 G0^9:0 B0^9:0 R1^3:0 R0^10 B2^4 G2^3:0 G1^3:0 G0^10 B3^0 G3^3:0 B1^4:0 B0^10 B2^3:0 R2^3:0 B3^1 B3^2 "
     "R3^3:0 B3^4 B3^3 PB^4:0"},
    {14,
     true,
     2,
     9,
     {5, 5, 5},
     "R0^8:0 B2^4 G0^8:0 G2^4 B0^8:0 B3^4 R1^4:0 G3^4 G2^3:0 G1^4:0 B3^0 G3^3:0 B1^4:0 B3^1 B2^3:0 R2^4:0 B3^2 "
     "R3^4:0 B3^3 PB^4:0"},
    {18,
     true,
     2,
     8,
     {6, 5, 5},
     "R0^7:0 G3^4 B2^4 G0^7:0 B3^2 G2^4 B0^7:0 B3^3 B3^4 R1^5:0 G2^3:0 G1^4:0 B3^0 G3^3:0 B1^4:0 B3^1 B2^3:0 R2^5:0 "
     "R3^5:0 PB^4:0"},
    {22,
     true,
     2,
     8,
     {5, 6, 5},
     "R0^7:0 B3^0 B2^4 G0^7:0 G2^5 G2^4 B0^7:0 G3^5 B3^4 R1^4:0 G3^4 G2^3:0 G1^5:0 G3^3:0 B1^4:0 B3^1 B2^3:0 R2^4:0 "
     "B3^2 R3^4:0 B3^3 PB^4:0"},
    {26,
     true,
     2,
     8,
     {5, 5, 6},
     "R0^7:0 B3^1 B2^4 G0^7:0 B2^5 G2^4 B0^7:0 B3^5 B3^4 R1^4:0 G3^4 G2^3:0 G1^4:0 B3^0 G3^3:0 B1^5:0 B2^3:0 R2^4:0 "
     "B3^2 R3^4:0 B3^3 PB^4:0"},
    {30,
     false,
     2,
     6,
     {0, 0, 0},
     "R0^5:0 G3^4 B3^0 B3^1 B2^4 G0^5:0 G2^5 B2^5 B3^2 G2^4 B0^5:0 G3^5 B3^3 B3^5 B3^4 R1^5:0 G2^3:0 G1^5:0 G3^3:0 "
     "B1^5:0 B2^3:0 R2^5:0 R3^5:0 PB^4:0"},
    {3, false, 1, 10, {0, 0, 0}, "R0^9:0 G0^9:0 B0^9:0 R1^9:0 G1^9:0 B1^9:0"},
    {7, true, 1, 11, {9, 9, 9}, "R0^9:0 G0^9:0 B0^9:0 R1^8:0 R0^10 G1^8:0 G0^10 B1^8:0 B0^10"},
    {11, true, 1, 12, {8, 8, 8}, "R0^9:0 G0^9:0 B0^9:0 R1^7:0 R0^10:11 G1^7:0 G0^10:11 B1^7:0 B0^10:11"},
    {15, true, 1, 16, {4, 4, 4}, "R0^9:0 G0^9:0 B0^9:0 R1^3:0 R0^10:15 G1^3:0 G0^10:15 B1^3:0 B0^10:15"},
};

// Field index: endpoint e's channel c is 3 * e + c; PB is 12.
struct Bc6Piece {
  uint32_t field, a, b;
};
std::vector<Bc6Piece> parseLayout(const char* layout) {
  std::vector<Bc6Piece> pieces;
  std::string s(layout);
  size_t pos = 0;
  while (pos < s.size()) {
    size_t end = s.find(' ', pos);
    if (end == std::string::npos) end = s.size();
    std::string tok = s.substr(pos, end - pos);
    pos = end + 1;
    uint32_t field = tok[0] == 'P' ? 12 : uint32_t(tok[1] - '0') * 3 + (tok[0] == 'R' ? 0 : tok[0] == 'G' ? 1 : 2);
    size_t colon = tok.find(':');
    uint32_t a = uint32_t(std::stoul(tok.substr(3, colon == std::string::npos ? std::string::npos : colon - 3)));
    uint32_t b = colon == std::string::npos ? a : uint32_t(std::stoul(tok.substr(colon + 1)));
    pieces.push_back({field, a, b});
  }
  return pieces;
}

// The width of each field in a mode: EPB for E0, the delta bits (transformed) or EPB for the others, 5 for PB.
uint32_t fieldWidth(const Bc6Params& m, uint32_t field) {
  if (field == 12) return m.regions == 2 ? 5 : 0;
  if (field / 3 >= 2 * m.regions) return 0;
  return field < 3 || !m.transformed ? m.epb : m.delta[field % 3];
}

// The layouts cover each field's bits exactly once, and the header ends where the indices begin.
TEST(BcDecode, Bc6hTestLayoutsAreConsistent) {
  for (const Bc6Params& m : kBc6Params) {
    uint32_t seen[13] = {}, total = m.mode < 2 ? 2 : 5;
    for (const Bc6Piece& p : parseLayout(m.layout)) {
      uint32_t lo = std::min(p.a, p.b), hi = std::max(p.a, p.b);
      for (uint32_t bit = lo; bit <= hi; ++bit) {
        EXPECT_FALSE(seen[p.field] & (1u << bit)) << "mode " << m.mode << " field " << p.field << " bit " << bit;
        seen[p.field] |= 1u << bit;
      }
      total += hi - lo + 1;
    }
    for (uint32_t f = 0; f < 13; ++f)
      EXPECT_EQ(seen[f], (1u << fieldWidth(m, f)) - 1) << "mode " << m.mode << " field " << f;
    EXPECT_EQ(total, m.regions == 2 ? 82u : 65u) << "mode " << m.mode;
  }
}

struct Bc6Fields {
  const Bc6Params* mode;
  uint32_t field[13] = {};
  uint32_t index[16] = {};
};

Bc6Fields randomBc6(Rng& rng, const Bc6Params& m) {
  Bc6Fields f{&m};
  for (uint32_t i = 0; i < 13; ++i) f.field[i] = rng.bits(fieldWidth(m, i));
  uint32_t bits = m.regions == 2 ? 3 : 4;
  for (uint32_t i = 0; i < 16; ++i) f.index[i] = rng.bits(bits - (anchorTexel(m.regions, f.field[12], i) ? 1 : 0));
  return f;
}

void encodeBc6(const Bc6Fields& f, uint8_t out[16]) {
  const Bc6Params& m = *f.mode;
  BitWriter w;
  w.put(m.mode, m.mode < 2 ? 2 : 5);
  for (const Bc6Piece& p : parseLayout(m.layout)) {
    int step = p.a >= p.b ? 1 : -1;  // from bit b towards bit a
    for (int bit = int(p.b);; bit += step) {
      w.put(f.field[p.field] >> bit, 1);
      if (bit == int(p.a)) break;
    }
  }
  EXPECT_EQ(w.pos(), m.regions == 2 ? 82u : 65u);
  uint32_t bits = m.regions == 2 ? 3 : 4;
  for (uint32_t i = 0; i < 16; ++i) w.put(f.index[i], bits - (anchorTexel(m.regions, f.field[12], i) ? 1 : 0));
  EXPECT_EQ(w.pos(), 128u);
  std::memcpy(out, w.data(), 16);
}

int32_t signExtendTo32(uint32_t v, uint32_t bits) {
  return (v & (1u << (bits - 1))) ? int32_t(v) - int32_t(1u << bits) : int32_t(v);
}

// The spec's unquantization pseudocode.
int32_t unquantizeUnsigned(int32_t x, uint32_t epb) {
  if (epb >= 15) return x;
  if (x == 0) return 0;
  if (x == int32_t((1u << epb) - 1)) return 0xFFFF;
  return ((x << 15) + 0x4000) >> (epb - 1);
}
int32_t unquantizeSigned(int32_t x, uint32_t epb) {
  if (epb >= 16) return x;
  bool s = x < 0;
  if (s) x = -x;
  int32_t unq;
  if (x == 0)
    unq = 0;
  else if (x >= int32_t((1u << (epb - 1)) - 1))
    unq = 0x7FFF;
  else
    unq = ((x << 15) + 0x4000) >> (epb - 1);
  return s ? -unq : unq;
}

// An IEEE half's value, from its fields.
float halfValue(uint32_t h) {
  double sign = (h & 0x8000) ? -1.0 : 1.0;
  uint32_t e = (h >> 10) & 31, mant = h & 1023;
  if (e == 31) return mant ? std::numeric_limits<float>::quiet_NaN() : float(sign * HUGE_VAL);
  if (e == 0) return float(sign * std::ldexp(double(mant), -24));
  return float(sign * std::ldexp(1.0 + mant / 1024.0, int(e) - 15));
}

// The expected half-float bit patterns of the block's texels.
void expectBc6(const Bc6Fields& f, bool isSigned, uint32_t half[16][3]) {
  const Bc6Params& m = *f.mode;
  int32_t ep[4][3];
  uint32_t mask = (1u << m.epb) - 1;
  for (uint32_t e = 0; e < 2 * m.regions; ++e)
    for (uint32_t c = 0; c < 3; ++c) {
      uint32_t raw = f.field[3 * e + c];
      int32_t v;
      if (e == 0)
        v = isSigned ? signExtendTo32(raw, m.epb) : int32_t(raw);
      else if (m.transformed) {
        int32_t sum = (f.field[c] + signExtendTo32(raw, m.delta[c])) & int32_t(mask);  // wrapped at EPB bits
        v = isSigned ? signExtendTo32(uint32_t(sum), m.epb) : sum;
      } else {
        v = isSigned ? signExtendTo32(raw, m.epb) : int32_t(raw);
      }
      ep[e][c] = isSigned ? unquantizeSigned(v, m.epb) : unquantizeUnsigned(v, m.epb);
    }
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t s = subsetOfTexel(m.regions, f.field[12], i);
    uint32_t w = bptcWeight(m.regions == 2 ? 3 : 4, f.index[i]);
    for (uint32_t c = 0; c < 3; ++c) {
      int32_t v = bptcInterpolate(ep[2 * s][c], ep[2 * s + 1][c], w);
      if (!isSigned)
        half[i][c] = uint32_t(v * 31) >> 6;
      else
        half[i][c] = v < 0 ? (uint32_t(-v * 31) >> 5) | 0x8000 : uint32_t(v * 31) >> 5;
    }
  }
}

void checkBc6(const Bc6Fields& f, bool isSigned) {
  uint8_t block[16];
  encodeBc6(f, block);
  uint32_t want[16][3];
  expectBc6(f, isSigned, want);
  Texels got = decode(isSigned ? Kind::BC6H_SFLOAT : Kind::BC6H_UFLOAT, block);
  for (int i = 0; i < 16; ++i) {
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(got.t[i][c], halfValue(want[i][c]))
          << (isSigned ? "signed" : "unsigned") << " mode " << f.mode->mode << " partition " << f.field[12] << " texel "
          << i << " channel " << c << " half 0x" << std::hex << want[i][c];
    ASSERT_EQ(got.t[i][3], 1.0f);
  }
}

TEST(BcDecode, Bc6hEveryModeRandomFields) {
  Rng rng{0xBC6};
  for (const Bc6Params& m : kBc6Params)
    for (bool isSigned : {false, true})
      for (int n = 0; n < 300; ++n) checkBc6(randomBc6(rng, m), isSigned);
}

// Two-region modes over all 32 partitions (with their anchors), signed and unsigned.
TEST(BcDecode, Bc6hEveryPartition) {
  Rng rng{0x6};
  for (uint32_t k : {0u, 1u, 9u})  // modes 0, 1 and 30
    for (uint32_t p = 0; p < 32; ++p)
      for (bool isSigned : {false, true}) {
        Bc6Fields f = randomBc6(rng, kBc6Params[k]);
        f.field[12] = p;
        for (uint32_t i = 0; i < 16; ++i) f.index[i] = rng.bits(3 - (anchorTexel(2, p, i) ? 1 : 0));
        checkBc6(f, isSigned);
      }
}

// Mode 0 with deltas that wrap: R0 = 1020 plus R1's +15 gives 1035 & 1023 = 11; G1's -16 from G0 = 3 gives -13,
// & 1023 = 1011 (unsigned) or -13 (signed).
TEST(BcDecode, Bc6hMode0DeltaWrap) {
  for (bool isSigned : {false, true}) {
    Bc6Fields f{&kBc6Params[0]};
    f.field[0] = 1020;  // R0
    f.field[1] = 3;     // G0
    f.field[3] = 15;    // R1: +15
    f.field[4] = 16;    // G1: -16 in 5 bits
    for (int i = 0; i < 16; ++i) f.index[i] = i == 0 ? 0 : 7 * (i & 1);
    checkBc6(f, isSigned);
  }
}

// Hand-computed values: mode 3 (one region, 10-bit endpoints, not transformed) from 0 to 1023, which
// unquantizes to 0xFFFF: weight 64 (index 15) gives (0xFFFF * 31) >> 6 = 0x7BFF = 65504.0; weight 34 (index 8)
// gives (34 * 65535 + 32) >> 6 = 34815, then (34815 * 31) >> 6 = 16863 = 0x41DF = 2 * (1 + 479 / 1024).
TEST(BcDecode, Bc6hMode3KnownValues) {
  Bc6Fields f{&kBc6Params[10]};
  f.field[3] = f.field[4] = f.field[5] = 1023;
  for (uint32_t i = 0; i < 16; ++i) f.index[i] = i;
  uint8_t block[16];
  encodeBc6(f, block);
  Texels u = decode(Kind::BC6H_UFLOAT, block);
  EXPECT_EQ(u.t[0][0], 0.0f);
  EXPECT_EQ(u.t[15][0], 65504.0f);
  EXPECT_EQ(u.t[8][1], 2.935546875f);
  // Signed: 1023 is -1 (-> -unquantized 1: ((1 << 15) + 0x4000) >> 9 = 96 -> (96 * 31) >> 5 = 93, negative:
  // 0x805D), and E0 = 0x200 = -512 saturates to -0x7FFF -> 0xFBFF = -65504.
  f.field[0] = 0x200;
  encodeBc6(f, block);
  Texels s = decode(Kind::BC6H_SFLOAT, block);
  EXPECT_EQ(s.t[0][0], -65504.0f);
  EXPECT_EQ(s.t[15][1], -93.0f / 16777216.0f);  // 0x805D: a negative subnormal, -93 * 2^-24
  checkBc6(f, true);
}

// Reserved mode numbers 19, 23, 27 and 31 decode to (0, 0, 0, 1) whatever the other bits are.
TEST(BcDecode, Bc6hReservedModes) {
  Rng rng{0x19};
  for (uint32_t mode : {19u, 23u, 27u, 31u})
    for (Kind kind : {Kind::BC6H_UFLOAT, Kind::BC6H_SFLOAT}) {
      uint8_t block[16];
      for (uint8_t& b : block) b = uint8_t(rng.bits(8));
      block[0] = uint8_t((block[0] & ~31u) | mode);
      Texels got = decode(kind, block);
      for (int i = 0; i < 16; ++i) expectTexel(got.t[i], 0, 0, 0, 1, 0, "mode " + std::to_string(mode));
    }
}

// ---- Published reference blocks ----

// BC7 blocks of tinybcdec's src/test/resources/bc7.dds (256x256), one per mode, with the texels of the decoded image
// stored beside it (bc7.png), each as 0xAABBGGRR. The comment gives the block's index in raster order.
struct Bc7Reference {
  uint8_t block[16];
  uint32_t rgba[16];
};
const Bc7Reference kBc7References[] = {
    // mode 0, block 1171
    {{0x07, 0xee, 0x10, 0x02, 0xee, 0x10, 0x02, 0xfc, 0x01, 0xc4, 0x04, 0x00, 0xd0, 0x53, 0xe0, 0x00},
     {0xff000000, 0xff000000, 0xff000000, 0xff000000, 0xff000000, 0xff000000, 0xff0c0707, 0xff291818, 0xff221111,
      0xffac5858, 0xffff7b7b, 0xffff7b7b, 0xffef7b7b, 0xffff7b7b, 0xffff7b7b, 0xffff7b7b}},
    // mode 1, block 1107
    {{0x2e, 0xe0, 0x01, 0x4c, 0xe0, 0x01, 0x4c, 0xbf, 0x03, 0x98, 0x00, 0x00, 0x00, 0x90, 0xfd, 0x00},
     {0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181, 0xfffd8181,
      0xffe17373, 0xffaa5656, 0xff994c4c, 0xff381c1c, 0xff000000, 0xff000000, 0xff000000}},
    // mode 2, block 1360
    {{0xc4, 0x21, 0x78, 0x01, 0x28, 0x08, 0x5e, 0x00, 0xea, 0x03, 0x2f, 0x00, 0xc5, 0xe3, 0x0f, 0x00},
     {0xffff8484, 0xfff77b7b, 0xff100808, 0xff000000, 0xffff8484, 0xfff77b7b, 0xff100808, 0xff000000, 0xffa55252,
      0xff361b1b, 0xff000000, 0xff000000, 0xff000000, 0xff000000, 0xff000000, 0xff000000}},
    // mode 3, block 0
    {{0x08, 0x00, 0x81, 0x40, 0x20, 0x10, 0x08, 0x04, 0xfe, 0xff, 0xff, 0x3f, 0x00, 0x00, 0x00, 0x00},
     {0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080,
      0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080, 0xfffe8080}},
    // mode 4, block 1242
    {{0x90, 0xed, 0xb5, 0xa7, 0xfd, 0x9e, 0xa3, 0x28, 0x4b, 0xd3, 0x69, 0xdb, 0x96, 0x2d, 0x59, 0x92},
     {0xefd66b6b, 0xefee7777, 0xecee7777, 0xecee7777, 0xefee7777, 0xecee7777, 0xecee7777, 0xeae97474, 0xecee7777,
      0xecee7777, 0xeae97474, 0xeae97474, 0xecee7777, 0xeae97474, 0xeae97474, 0xe7e97474}},
    // mode 5, block 51
    {{0xe0, 0xb3, 0xd8, 0x2c, 0x56, 0x16, 0x2f, 0x0f, 0x23, 0x49, 0xd3, 0xf5, 0x51, 0x94, 0xa5, 0xe9},
     {0xcbcb6666, 0xcbcb6666, 0xc9c86565, 0xc7c86363, 0xcbcb6666, 0xc9c86565, 0xc7c86363, 0xc7c66363, 0xc9c86565,
      0xc7c86363, 0xc7c66363, 0xc5c66262, 0xc7c86363, 0xc7c66363, 0xc5c66262, 0xc5c36262}},
    // mode 6, block 42
    {{0x40, 0xa0, 0x0f, 0xe8, 0xfb, 0xf3, 0xff, 0x7c, 0x13, 0x41, 0x11, 0xa4, 0x41, 0xaa, 0xa4, 0xfa},
     {0xfefe8080, 0xfefe8080, 0xfefe8080, 0xfdfd7f7f, 0xfefe8080, 0xfefe8080, 0xfdfd7f7f, 0xfbfb7e7e, 0xfefe8080,
      0xfdfd7f7f, 0xfbfb7e7e, 0xfbfb7e7e, 0xfdfd7f7f, 0xfbfb7e7e, 0xfbfb7e7e, 0xf9f97d7d}},
    // mode 7, block 1023
    {{0x80, 0x88, 0x10, 0x42, 0x08, 0x21, 0x44, 0x19, 0xa4, 0x14, 0x42, 0xc8, 0x28, 0x4b, 0x53, 0x55},
     {0x2c2c1414, 0x29271414, 0x29271414, 0x27211414, 0x29271414, 0x29271414, 0x27211414, 0x27211414, 0x29271414,
      0x27211414, 0x27211414, 0x20251010, 0x27211414, 0x27211414, 0x20251010, 0x20201010}},
};

// BC6H blocks of tinybcdec's bc6h_uf16.dds and bc6h_sf16.dds (256x256) with the half floats (R, G, B per texel) of
// the decoded images stored beside them (level 0 of bc6h_uf16_16.dds and bc6h_sf16_16.dds).
struct Bc6Reference {
  bool isSigned;
  uint8_t block[16];
  uint16_t rgb[48];
};
const Bc6Reference kBc6References[] = {
    // bc6h_uf16.dds, mode 0, block 14
    {false,
     {0x20, 0xba, 0xe8, 0xde, 0x0b, 0x23, 0x78, 0x00, 0x82, 0x0f, 0xbc, 0x64, 0x4d, 0xda, 0xa4, 0x0d},
     {0x386b, 0x386b, 0x3c00, 0x386b, 0x386b, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00,
      0x386b, 0x386b, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00,
      0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00,
      0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x3874, 0x3874, 0x3c00, 0x387d, 0x387d, 0x3c00}},
    // bc6h_uf16.dds, mode 3, block 1
    {false,
     {0xc3, 0x39, 0xe7, 0xde, 0x7b, 0xee, 0xb9, 0xf7, 0x12, 0x55, 0x51, 0x55, 0x55, 0x55, 0x55, 0x95},
     {0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00,
      0x3803, 0x3803, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00,
      0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00,
      0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x380b, 0x380b, 0x3c00, 0x3813, 0x3813, 0x3c00}},
    // bc6h_uf16.dds, mode 11, block 3
    {false,
     {0x8b, 0x67, 0x9e, 0x7b, 0x17, 0x50, 0xc0, 0x00, 0x13, 0x77, 0x71, 0x77, 0x77, 0x77, 0x77, 0xe7},
     {0x3815, 0x3815, 0x3bfd, 0x3815, 0x3815, 0x3bfd, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00,
      0x3815, 0x3815, 0x3bfd, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00,
      0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00,
      0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00, 0x381c, 0x381c, 0x3c00, 0x3823, 0x3823, 0x3c03}},
    // bc6h_uf16.dds, mode 26, block 2783
    {false,
     {0x7a, 0x8d, 0x35, 0xda, 0xfc, 0xfa, 0x67, 0xc0, 0x1b, 0x46, 0x98, 0x84, 0x49, 0x98, 0x84, 0x49},
     {0x33ef, 0x33ef, 0x350a, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06,
      0x33ca, 0x33ca, 0x350a, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06,
      0x33ca, 0x33ca, 0x350a, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06,
      0x33ca, 0x33ca, 0x350a, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06, 0x3a4c, 0x3a4c, 0x3c06}},
    // bc6h_sf16.dds, mode 1, block 1096
    {true,
     {0xb5, 0xe3, 0x4e, 0x3d, 0xa2, 0x9d, 0x9e, 0xfa, 0xfd, 0xd1, 0x02, 0x00, 0x00, 0x08, 0xf0, 0x5f},
     {0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18,
      0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18,
      0x3548, 0x3548, 0x3928, 0x35e3, 0x35e3, 0x3818, 0x3928, 0x3928, 0x3b18, 0x3928, 0x3928, 0x3b18,
      0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x21e8, 0x21e8, 0x25c8, 0x329e, 0x329e, 0x3519}},
    // bc6h_sf16.dds, mode 7, block 0
    {true,
     {0xc7, 0x39, 0xe7, 0xde, 0x0b, 0x20, 0x00, 0x00, 0x12, 0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x51},
     {0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00,
      0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00,
      0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00,
      0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x3803, 0x3803, 0x3c00, 0x380c, 0x380c, 0x3c00}},
    // bc6h_sf16.dds, mode 10, block 1088
    {true,
     {0x4a, 0x3a, 0xe9, 0xde, 0x0b, 0x37, 0x0c, 0xe0, 0x96, 0x00, 0xa9, 0x4d, 0xdb, 0xb6, 0x79, 0x33},
     {0x3886, 0x3886, 0x3c00, 0x3886, 0x3886, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00,
      0x3886, 0x3886, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00,
      0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x3882, 0x3882, 0x3bf3,
      0x388b, 0x388b, 0x3c00, 0x388b, 0x388b, 0x3c00, 0x3882, 0x3882, 0x3bf3, 0x37e2, 0x37e2, 0x3ae9}},
    // bc6h_sf16.dds, mode 30, block 1095
    {true,
     {0xde, 0x11, 0x87, 0x1e, 0x69, 0xa0, 0x61, 0x07, 0x00, 0xe6, 0x01, 0x00, 0x00, 0x10, 0xf6, 0x00},
     {0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10,
      0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10, 0x3830, 0x3830, 0x3c10,
      0x3830, 0x3830, 0x3c10, 0x37a4, 0x37a4, 0x3b84, 0x35f2, 0x35f2, 0x39d2, 0x3567, 0x3567, 0x3947,
      0x3070, 0x3070, 0x3450, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000, 0x0000}},
};

TEST(BcDecode, Bc7PublishedReferenceBlocks) {
  for (const Bc7Reference& r : kBc7References) {
    Texels got = decode(Kind::BC7, r.block);
    for (int i = 0; i < 16; ++i)
      for (int c = 0; c < 4; ++c)
        EXPECT_NEAR(got.t[i][c], ((r.rgba[i] >> (8 * c)) & 255) / 255.0, kTol)
            << "mode byte 0x" << std::hex << int(r.block[0]) << std::dec << " texel " << i << " channel " << c;
  }
}

TEST(BcDecode, Bc6hPublishedReferenceBlocks) {
  for (const Bc6Reference& r : kBc6References) {
    Texels got = decode(r.isSigned ? Kind::BC6H_SFLOAT : Kind::BC6H_UFLOAT, r.block);
    for (int i = 0; i < 16; ++i) {
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(got.t[i][c], halfValue(r.rgb[3 * i + c]))
            << (r.isSigned ? "signed" : "unsigned") << " mode byte 0x" << std::hex << int(r.block[0]) << std::dec
            << " texel " << i << " channel " << c;
      EXPECT_EQ(got.t[i][3], 1.0f);
    }
  }
}

// The spec's worked example (BC7 section): in mode 2 with partition 6, texel (1, 2), index 9, is in subset 1
// (endpoints 2 and 3) and its 2-bit index is in bits 115 and 116 of the block. Endpoint 3 white, everything else
// zero: only texel 9, with index 3 (weight 64), is white; every other texel has index 0 and is black.
TEST(BcDecode, Bc7SpecWorkedExample) {
  BitWriter w;
  w.put(0b100, 3);  // mode 2
  w.put(6, 6);      // partition 6
  uint8_t block[16];
  std::memcpy(block, w.data(), 16);
  auto set = [&](uint32_t bit) { block[bit / 8] |= uint8_t(1u << (bit % 8)); };
  for (uint32_t first : {24u, 54u, 84u})  // R3 = bits 24..28, G3 = 54..58, B3 = 84..88
    for (uint32_t bit = first; bit < first + 5; ++bit) set(bit);
  set(115);
  set(116);
  Texels got = decode(Kind::BC7, block);
  for (int i = 0; i < 16; ++i) {
    double v = i == 9 ? 1.0 : 0.0;
    expectTexel(got.t[i], v, v, v, 1.0, kTol, "texel " + std::to_string(i));
  }
}

// ---- All kinds ----

// Random blocks of every kind: in range, finite (BC6H signed may give -infinity), and only blockBytes read (the
// heap copy in decode() lets AddressSanitizer see any read past it).
TEST(BcDecode, RandomBlocksStayInRange) {
  Rng rng{42};
  for (Kind kind : {Kind::BC1_RGB, Kind::BC1_RGBA, Kind::BC2, Kind::BC3, Kind::BC4_UNORM, Kind::BC4_SNORM,
                    Kind::BC5_UNORM, Kind::BC5_SNORM, Kind::BC6H_UFLOAT, Kind::BC6H_SFLOAT, Kind::BC7})
    for (int n = 0; n < 2000; ++n) {
      uint8_t block[16];
      for (uint8_t& b : block) b = uint8_t(rng.bits(8));
      Texels got = decode(kind, block);
      bool isSnorm = kind == Kind::BC4_SNORM || kind == Kind::BC5_SNORM;
      for (int i = 0; i < 16; ++i)
        for (int c = 0; c < 4; ++c) {
          float v = got.t[i][c];
          if (kind == Kind::BC6H_UFLOAT) {
            ASSERT_TRUE(v >= 0.0f && v <= 65504.0f) << v;
          } else if (kind == Kind::BC6H_SFLOAT) {
            ASSERT_TRUE(v >= -std::numeric_limits<float>::infinity() && v <= 65504.0f) << v;
          } else {
            ASSERT_TRUE(v >= (isSnorm ? -1.0f : 0.0f) && v <= 1.0f) << v;
          }
        }
      if (kind == Kind::BC4_UNORM || kind == Kind::BC4_SNORM)
        for (int i = 0; i < 16; ++i) expectTexel(got.t[i], got.t[i][0], 0, 0, 1, 0, "BC4 layout");
      if (kind == Kind::BC5_UNORM || kind == Kind::BC5_SNORM)
        for (int i = 0; i < 16; ++i) expectTexel(got.t[i], got.t[i][0], got.t[i][1], 0, 1, 0, "BC5 layout");
    }
}

TEST(BcDecode, BlockBytes) {
  EXPECT_EQ(blockBytes(Kind::BC1_RGB), 8u);
  EXPECT_EQ(blockBytes(Kind::BC1_RGBA), 8u);
  EXPECT_EQ(blockBytes(Kind::BC4_UNORM), 8u);
  EXPECT_EQ(blockBytes(Kind::BC4_SNORM), 8u);
  for (Kind k :
       {Kind::BC2, Kind::BC3, Kind::BC5_UNORM, Kind::BC5_SNORM, Kind::BC6H_UFLOAT, Kind::BC6H_SFLOAT, Kind::BC7})
    EXPECT_EQ(blockBytes(k), 16u);
}

}  // namespace
}  // namespace vkrt::bc
