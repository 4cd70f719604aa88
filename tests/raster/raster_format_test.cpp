// The back end's inline colour codecs (ColorFormat::layout, RGBA8 and BGRA8 UNorm) against the runtime's texel codecs
// (decodeTexel/encodeTexel, which the graphics layer passes as decode/encode): the same draw, once through each, writes
// the same bytes, for every stored byte value, out-of-range and NaN sources, blending, write masks and logic ops.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_harness.hpp"
#include "raster_runtime_codecs.hpp"

namespace vkrt::raster::test {
namespace {

// Codecs a draw must not reach (the layout's inline path replaces them).
void decodeWrong(const void*, const uint8_t*, uint32_t out[4]) { std::memset(out, 0, 16); }
void encodeWrong(const void*, const uint32_t*, uint8_t* t) { std::memset(t, 0x55, 4); }

struct Case {
  Vec4 source;
  bool blend;
  uint8_t writeMask;
  bool logic;
};

// A 16x16 RGBA8/BGRA8 target whose texels hold every byte value (texel i: bytes i, 255 - i, 3i, 7i + 1), covered by
// two triangles writing `c.source`; returns the target's bytes.
std::vector<uint8_t> render(VkFormat vkFormat, ColorFormat::Layout layout, const Case& c, bool wrongCodecs = false) {
  Harness h(16, 16);
  h.color = Image(16, 16, 4);
  for (uint32_t i = 0; i < 256; ++i) {
    uint8_t* p = h.color.data.data() + 4 * i;
    p[0] = uint8_t(i), p[1] = uint8_t(255 - i), p[2] = uint8_t(3 * i), p[3] = uint8_t(7 * i + 1);
  }
  ColorFormat& f = h.target.colorFormat[0];
  f.kind = ColorFormat::Kind::UNorm;
  f.texelBytes = 4;
  f.format = formatInfo(vkFormat);
  f.decode = wrongCodecs ? decodeWrong : decodeRuntime;
  f.encode = wrongCodecs ? encodeWrong : encodeRuntime;
  f.layout = layout;
  h.constant = c.source;
  BlendAttachment& b = h.state.blend[0];
  b.enable = c.blend;
  b.srcColor = BlendFactor::SrcAlpha, b.dstColor = BlendFactor::OneMinusSrcAlpha;
  b.srcAlpha = BlendFactor::One, b.dstAlpha = BlendFactor::OneMinusDstAlpha;
  b.writeMask = c.writeMask;
  h.state.logicOpEnable = c.logic;
  h.state.logicOp = LogicOp::Xor;
  h.vertex(0, 0), h.vertex(16, 0), h.vertex(0, 16);
  h.vertex(16, 0), h.vertex(16, 16), h.vertex(0, 16);
  h.run();
  return h.color.data;
}

TEST(RasterFormat, Unorm8LayoutsWriteWhatTheFormatCodecsWrite) {
  const float nan = std::nanf("");
  const Case cases[] = {
      {{0.25f, 0.5f, 0.75f, 1.0f}, false, 0xF, false},
      {{0.5f / 255, 1.5f / 255, 2.5f / 255, 254.5f / 255}, false, 0xF, false},  // halfway values round to even
      {{-0.5f, 2.0f, nan, 0.999f}, false, 0xF, false},                          // clamped; NaN writes 0
      {{0.3f, 0.6f, 0.9f, 0.45f}, true, 0xF, false},                            // src-alpha blending
      {{1.2f, -0.1f, 0.33f, 0.7f}, true, 0b1010, false},                        // blending, G and A written
      {{0.3f, 0.6f, 0.9f, 0.45f}, false, 0b0101, false},                        // R and B written
      {{1.0f, 0.0f, 0.5f, 0.2f}, false, 0xF, true},                             // logic op XOR
      {{1.0f, 0.0f, 0.5f, 0.2f}, true, 0b0011, true},                           // XOR with a write mask
  };
  for (const auto& [vkFormat, layout] : {std::pair{VK_FORMAT_R8G8B8A8_UNORM, ColorFormat::Layout::RGBA8UNorm},
                                         std::pair{VK_FORMAT_B8G8R8A8_UNORM, ColorFormat::Layout::BGRA8UNorm}}) {
    for (size_t i = 0; i < std::size(cases); ++i) {
      const std::vector<uint8_t> generic = render(vkFormat, ColorFormat::Layout::Generic, cases[i]);
      const std::vector<uint8_t> inline_ = render(vkFormat, layout, cases[i]);
      ASSERT_EQ(generic.size(), inline_.size());
      for (size_t b = 0; b < generic.size(); ++b)
        ASSERT_EQ(int(generic[b]), int(inline_[b])) << "format " << vkFormat << " case " << i << " byte " << b;
    }
  }
  // The inline path is what ran: with codecs that would write 0x55, the layout's draw writes the values the format's
  // rule gives (components times 255, rounded to nearest even), computed here by hand.
  const std::vector<uint8_t> out = render(VK_FORMAT_B8G8R8A8_UNORM, ColorFormat::Layout::BGRA8UNorm,
                                          {{0.25f, 0.5f, 0.75f, 1.0f}, true, 0xF, false}, true);
  // Alpha 1 blended with SRC_ALPHA / ONE_MINUS_SRC_ALPHA over texel 0 (B 0, G 255, R 0, A 1): the source alone;
  // alpha ONE / ONE_MINUS_DST_ALPHA: 1 + (1 - 1/255) * 1/255, clamped to 1.
  EXPECT_EQ(out[0], 191);  // B: 0.75 * 255 = 191.25
  EXPECT_EQ(out[1], 128);  // G: 127.5 rounds to even
  EXPECT_EQ(out[2], 64);   // R: 63.75
  EXPECT_EQ(out[3], 255);
}

// Every blend factor (a different one for color and alpha, source and destination) and op through the inline path
// of the 8-bit layouts (four components at once, raster/backend.cpp writeUnorm8) and through the runtime's codecs
// with the generic per-component blend: the same bytes, over every stored byte value, with 1 and 4 samples.
std::vector<uint8_t> renderBlend(VkFormat vkFormat, ColorFormat::Layout layout, const BlendAttachment& blend,
                                 uint32_t samples) {
  Harness h(16, 16, samples);
  h.color = Image(16, 16, 4, samples);
  for (size_t i = 0; i < h.color.data.size(); ++i) h.color.data[i] = uint8_t(i * 7 + i / 4);
  ColorFormat& f = h.target.colorFormat[0];
  f.kind = ColorFormat::Kind::UNorm;
  f.texelBytes = 4;
  f.format = formatInfo(vkFormat);
  f.decode = decodeRuntime;
  f.encode = encodeRuntime;
  f.layout = layout;
  h.constant = {0.8f, -0.2f, 0.45f, 0.6f};  // G below 0: clamped before blending
  h.constant1 = {0.1f, 0.9f, 1.5f, 0.3f};
  const float k[4] = {0.25f, 0.5f, 0.125f, 0.7f};
  std::memcpy(h.state.blendConstants, k, 16);
  h.state.blend[0] = blend;
  h.vertex(0, 0), h.vertex(16, 0), h.vertex(0, 16);
  h.vertex(16, 0), h.vertex(16, 16), h.vertex(0, 16);
  h.run();
  return h.color.data;
}

TEST(RasterFormat, Unorm8LayoutsBlendEveryFactorAndOpAsTheGenericPath) {
  constexpr int kFactors = int(BlendFactor::OneMinusSrc1Alpha) + 1;
  for (const auto& [vkFormat, layout] : {std::pair{VK_FORMAT_R8G8B8A8_UNORM, ColorFormat::Layout::RGBA8UNorm},
                                         std::pair{VK_FORMAT_B8G8R8A8_UNORM, ColorFormat::Layout::BGRA8UNorm}}) {
    for (uint32_t samples : {1u, 4u}) {
      for (int f = 0; f < kFactors; ++f) {
        for (int op = 0; op < 5; ++op) {
          BlendAttachment b;
          b.enable = true;
          b.srcColor = BlendFactor(f), b.dstColor = BlendFactor((f + 5) % kFactors);
          b.srcAlpha = BlendFactor((f + 3) % kFactors), b.dstAlpha = BlendFactor((f + 11) % kFactors);
          b.colorOp = BlendOp(op), b.alphaOp = BlendOp((op + 2) % 5);
          b.writeMask = f % 3 == 0 ? 0xF : uint8_t(1 + f % 15);
          const std::vector<uint8_t> generic = renderBlend(vkFormat, ColorFormat::Layout::Generic, b, samples);
          const std::vector<uint8_t> inline_ = renderBlend(vkFormat, layout, b, samples);
          ASSERT_EQ(generic, inline_) << "format " << vkFormat << " samples " << samples << " factor " << f << " op "
                                      << op;
        }
      }
    }
  }
  // And one case against a value computed here: SRC_ALPHA / ONE_MINUS_SRC_ALPHA, ADD over stored byte 0x40 of R.
  BlendAttachment b;
  b.enable = true;
  b.srcColor = BlendFactor::SrcAlpha, b.dstColor = BlendFactor::OneMinusSrcAlpha;
  const std::vector<uint8_t> out = renderBlend(VK_FORMAT_R8G8B8A8_UNORM, ColorFormat::Layout::RGBA8UNorm, b, 1);
  // Texel 0's R byte was 0: 0.8 * 0.6 + 0 * 0.4 = 0.48 -> 122.4 -> 122.
  EXPECT_EQ(out[0], 122);
}

// The packed 16-bit colour attachment formats the spec requires with blending (R5G6B5_UNORM_PACK16 and
// A1R5G5B5_UNORM_PACK16, "Mandatory Format Support: Sub-Byte Components"; B4G4R4A4 by the same codecs): a blended
// draw through the runtime's texel codecs, as the graphics layer passes them, against the blend equation computed
// here from the fields' bit positions in formats.adoc.
// A field of a 16-bit word: `bits` wide at bit `shift`.
struct Field {
  int shift, bits;
};
struct Layout {
  VkFormat format;
  Field rgba[4];  // bits 0 for a component the format lacks (alpha reads 1)
};

TEST(RasterPackedFormat, SixteenBitAttachmentsBlendWithTheirFieldsPrecision) {
  const Layout layouts[] = {
      {VK_FORMAT_R5G6B5_UNORM_PACK16, {{11, 5}, {5, 6}, {0, 5}, {0, 0}}},
      {VK_FORMAT_A1R5G5B5_UNORM_PACK16, {{10, 5}, {5, 5}, {0, 5}, {15, 1}}},
      {VK_FORMAT_B4G4R4A4_UNORM_PACK16, {{4, 4}, {8, 4}, {12, 4}, {0, 4}}},
  };
  const Vec4 source = {0.9f, 0.3f, 0.55f, 0.6f};
  for (const Layout& l : layouts) {
    SCOPED_TRACE(l.format);
    Harness h(16, 16);
    h.color = Image(16, 16, 2);
    for (uint32_t i = 0; i < 256; ++i) {
      const uint16_t w = uint16_t(i * 257 + 11 * i * i);  // every byte value in each byte, scattered
      std::memcpy(h.color.data.data() + 2 * i, &w, 2);
    }
    const std::vector<uint8_t> before = h.color.data;
    ColorFormat& f = h.target.colorFormat[0];
    f.kind = ColorFormat::Kind::UNorm;
    f.texelBytes = 2;
    f.format = formatInfo(l.format);
    ASSERT_NE(f.format, nullptr);
    f.componentMask = uint8_t((1u << formatInfo(l.format)->components) - 1);
    f.decode = decodeRuntime;
    f.encode = encodeRuntime;
    h.constant = source;
    BlendAttachment& b = h.state.blend[0];
    b.enable = true;
    b.srcColor = BlendFactor::SrcAlpha, b.dstColor = BlendFactor::OneMinusSrcAlpha;
    b.srcAlpha = BlendFactor::One, b.dstAlpha = BlendFactor::OneMinusSrcAlpha;
    b.writeMask = 0xF;
    h.vertex(0, 0), h.vertex(16, 0), h.vertex(0, 16);
    h.vertex(16, 0), h.vertex(16, 16), h.vertex(0, 16);
    h.run();
    int bad = 0;
    for (uint32_t i = 0; i < 256; ++i) {
      uint16_t d, g;
      std::memcpy(&d, before.data() + 2 * i, 2);
      std::memcpy(&g, h.color.data.data() + 2 * i, 2);
      for (int c = 0; c < 4; ++c) {
        const Field fl = l.rgba[c];
        if (!fl.bits) continue;
        const double max = double((1 << fl.bits) - 1);
        const double dst = double((d >> fl.shift) & ((1 << fl.bits) - 1)) / max;
        const double a = source[3];
        const double want = c < 3 ? source[c] * a + dst * (1 - a) : a + dst * (1 - a);
        const int got = (g >> fl.shift) & ((1 << fl.bits) - 1);
        // The correctly rounded field, or either neighbour at a tie (float arithmetic within 1e-3 of x.5).
        if (std::fabs(got - want * max) > 0.5 + 1e-3 && bad++ < 8)
          ADD_FAILURE() << "texel " << i << " component " << c << ": got " << got << ", want " << want * max;
      }
    }
    EXPECT_EQ(bad, 0);
  }
}

}  // namespace
}  // namespace vkrt::raster::test
