// The packed 16-bit colour attachment formats the spec requires with blending (R5G6B5_UNORM_PACK16 and
// A1R5G5B5_UNORM_PACK16, "Mandatory Format Support: Sub-Byte Components"; B4G4R4A4 by the same codecs): a blended
// draw through the runtime's texel codecs, as the graphics layer passes them, against the blend equation computed
// here from the fields' bit positions in formats.adoc.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_harness.hpp"
#include "runtime/format.hpp"
#include "runtime/image_functions.hpp"

namespace vkrt::raster::test {
namespace {

void decodeRuntime(const void* f, const uint8_t* t, uint32_t out[4]) {
  decodeTexel(*static_cast<const FormatInfo*>(f), t, out);
}
void encodeRuntime(const void* f, const uint32_t in[4], uint8_t* t) {
  encodeTexel(*static_cast<const FormatInfo*>(f), in, t);
}

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
