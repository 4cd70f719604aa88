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
