// The per-fragment operations: depth test and write with every compare op and format, depth bias, stencil ops,
// blend factors and ops against their formulas, write masks, logic ops, early tests.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_harness.hpp"

namespace vkrt::raster::test {
namespace {

bool referenceCompare(CompareOp op, double a, double b) {
  switch (op) {
    case CompareOp::Never: return false;
    case CompareOp::Less: return a < b;
    case CompareOp::Equal: return a == b;
    case CompareOp::LessOrEqual: return a <= b;
    case CompareOp::Greater: return a > b;
    case CompareOp::NotEqual: return a != b;
    case CompareOp::GreaterOrEqual: return a >= b;
    case CompareOp::Always: return true;
  }
  return false;
}

// A full-screen quad (two triangles) at depth z over a small target.
void quad(Harness& h, float z) {
  h.vertex(0, 0, z), h.vertex(8, 0, z), h.vertex(0, 8, z);
  h.vertex(8, 0, z), h.vertex(8, 8, z), h.vertex(0, 8, z);
}

struct DepthSetup {
  Image depth;
  void attach(Harness& h, DepthFormat fmt) {
    const uint32_t bytes = fmt == DepthFormat::D16UNorm ? 2 : 4;
    depth = Image(h.width, h.height, bytes, h.samples);
    h.target.depthStencil.depthFormat = fmt;
    h.target.depthStencil.depth = depth.surface();
    h.target.depthStencil.depthTexelBytes = bytes;
  }
};

TEST(RasterDepth, EveryCompareOpAndFormat) {
  for (DepthFormat fmt : {DepthFormat::D16UNorm, DepthFormat::X8D24UNorm, DepthFormat::D32SFloat}) {
    for (int op = 0; op < 8; ++op) {
      for (float z : {0.25f, 0.5f, 0.75f}) {
        Harness h(8, 8);
        DepthSetup d;
        d.attach(h, fmt);
        // Stored depth 0.5 (as the format stores it); X8D24 keeps its top byte.
        for (uint32_t i = 0; i < 64; ++i) {
          uint8_t* p = d.depth.data.data() + i * d.depth.texelBytes;
          if (fmt == DepthFormat::D16UNorm) {
            const uint16_t v = 32768;  // round(0.5 * 65535)
            std::memcpy(p, &v, 2);
          } else if (fmt == DepthFormat::X8D24UNorm) {
            const uint32_t v = 0xAB000000u | 8388608u;  // round(0.5 * (2^24 - 1))
            std::memcpy(p, &v, 4);
          } else {
            const float v = 0.5f;
            std::memcpy(p, &v, 4);
          }
        }
        h.state.depthTest = true;
        h.state.depthWrite = true;
        h.state.depthCompare = CompareOp(op);
        quad(h, z);
        h.run();
        const bool pass = referenceCompare(CompareOp(op), z, 0.5);
        ASSERT_EQ(h.color.f(3, 3, 3), pass ? 1.0f : 0.0f) << int(fmt) << " op " << op << " z " << z;
        uint8_t* p = d.depth.at(3, 3);
        const double expectDepth = pass ? z : 0.5;
        if (fmt == DepthFormat::D16UNorm) {
          uint16_t v;
          std::memcpy(&v, p, 2);
          EXPECT_EQ(v, uint16_t(std::lround(expectDepth * 65535)));
        } else if (fmt == DepthFormat::X8D24UNorm) {
          uint32_t v;
          std::memcpy(&v, p, 4);
          EXPECT_EQ(v >> 24, 0xABu);
          EXPECT_EQ(v & 0xFFFFFF, uint32_t(std::lround(expectDepth * 16777215)));
        } else {
          float v;
          std::memcpy(&v, p, 4);
          EXPECT_EQ(v, float(expectDepth));
        }
      }
    }
  }
}

TEST(RasterDepth, ComparesAsStoredAndFragDepth) {
  // D16: a fragment depth within half a step of the stored value is Equal.
  Harness h(8, 8);
  DepthSetup d;
  d.attach(h, DepthFormat::D16UNorm);
  const uint16_t stored = 1000;
  for (uint32_t i = 0; i < 64; ++i) std::memcpy(d.depth.data.data() + 2 * i, &stored, 2);
  h.state.depthTest = true;
  h.state.depthCompare = CompareOp::Equal;
  quad(h, float((1000 + 0.3) / 65535));
  h.run();
  EXPECT_EQ(h.color.f(2, 2, 3), 1.0f);
  // FragDepth from the shader replaces the interpolated depth (clamped to [0, 1] for UNorm).
  Harness f(8, 8);
  DepthSetup fd;
  fd.attach(f, DepthFormat::D16UNorm);
  f.state.depthTest = f.state.depthWrite = true;
  f.state.depthCompare = CompareOp::Always;
  f.fs.writesDepth = true;
  f.fragDepthFromInput = true;
  quad(f, 0.5f);
  f.addInput(Interpolation::Flat, std::vector<Vec4>(6, Vec4{1.5f, 0, 0, 0}));
  f.run();
  uint16_t v;
  std::memcpy(&v, fd.depth.at(2, 2), 2);
  EXPECT_EQ(v, 65535);
}

TEST(RasterDepth, BiasConstantSlopeAndClamp) {
  // D32 (r = 2^(e - 23) with e = -1 for depths in [0.5, 1)): constant 1000 -> +1000 * 2^-24.
  {
    Harness h(8, 8);
    DepthSetup d;
    d.attach(h, DepthFormat::D32SFloat);
    h.state.depthTest = h.state.depthWrite = true;
    h.state.depthCompare = CompareOp::Always;
    h.state.depthBiasEnable = true;
    h.state.depthBiasConstant = 1000;
    quad(h, 0.5f);
    h.run();
    EXPECT_FLOAT_EQ(d.depth.f(3, 3), float(0.5 + 1000 * std::ldexp(1.0, -24)));
  }
  // D16 (r = 2^-16): constant 2, slope 3 on a plane with dz/dx = 1/64, clamp 0.04.
  for (float clampValue : {0.0f, 0.04f}) {
    Harness h(64, 8);
    DepthSetup d;
    d.attach(h, DepthFormat::D16UNorm);
    h.state.depthTest = h.state.depthWrite = true;
    h.state.depthCompare = CompareOp::Always;
    h.state.depthBiasEnable = true;
    h.state.depthBiasConstant = 2;
    h.state.depthBiasSlope = 3;
    h.state.depthBiasClamp = clampValue;
    h.vertex(0, 0, 0.25f), h.vertex(64, 0, 1.25f), h.vertex(0, 64, 0.25f);
    h.run();
    double bias = 3.0 / 64 + 2 * std::ldexp(1.0, -16);
    if (clampValue > 0) bias = std::min(bias, double(clampValue));
    const double z = 0.25 + 10.5 / 64 + bias;
    uint16_t v;
    std::memcpy(&v, d.depth.at(10, 2), 2);
    EXPECT_NEAR(v, z * 65535, 1.0) << clampValue;
  }
}

// A plane sloped in x and in y, written with one sample: each pixel's depth is the plane at its centre (both rows of
// each quad, quads of blocks inside the triangle and of blocks its edge crosses), within the plane's float rounding.
TEST(RasterDepth, SlopedPlaneAtEveryPixelCentre) {
  for (float extent : {40.0f, 20.0f}) {  // all of the 16x16 target, then a triangle whose edge crosses it
    Harness h(16, 16);
    DepthSetup d;
    d.attach(h, DepthFormat::D32SFloat);
    for (uint32_t i = 0; i < 256; ++i) {
      const float far = 2.0f;  // marks the pixels not written
      std::memcpy(d.depth.data.data() + 4 * i, &far, 4);
    }
    h.state.depthTest = h.state.depthWrite = true;
    h.state.depthCompare = CompareOp::Always;
    const double dzdx = 0.25 / 32, dzdy = 0.5 / 32;  // (every vertex inside the depth range: no clipping)
    h.vertex(0, 0, 0.125f), h.vertex(extent, 0, float(0.125 + extent * dzdx)),
        h.vertex(0, extent, float(0.125 + extent * dzdy));
    h.run();
    for (uint32_t y = 0; y < 16; ++y)
      for (uint32_t x = 0; x < 16; ++x) {
        const bool inside = x + 0.5 + y + 0.5 < extent;  // (no centre lies on the edge)
        const double z = inside ? 0.125 + (x + 0.5) * dzdx + (y + 0.5) * dzdy : 2.0;
        EXPECT_NEAR(d.depth.f(x, y), z, 1e-6) << "extent " << extent << " pixel " << x << "," << y;
      }
  }
}

TEST(RasterStencil, OpsMasksAndFaces) {
  const StencilOp ops[] = {StencilOp::Keep,
                           StencilOp::Zero,
                           StencilOp::Replace,
                           StencilOp::IncrementAndClamp,
                           StencilOp::DecrementAndClamp,
                           StencilOp::Invert,
                           StencilOp::IncrementAndWrap,
                           StencilOp::DecrementAndWrap};
  auto apply = [](StencilOp op, uint32_t s, uint32_t ref) -> uint32_t {
    switch (op) {
      case StencilOp::Keep: return s;
      case StencilOp::Zero: return 0;
      case StencilOp::Replace: return ref;
      case StencilOp::IncrementAndClamp: return std::min(s + 1, 255u);
      case StencilOp::DecrementAndClamp: return s ? s - 1 : 0;
      case StencilOp::Invert: return 255 - s;
      case StencilOp::IncrementAndWrap: return (s + 1) % 256;
      case StencilOp::DecrementAndWrap: return (s + 255) % 256;
    }
    return s;
  };
  // path 0: stencil fails (failOp); 1: depth fails (depthFailOp); 2: both pass (passOp). Initial 0 and 255.
  for (StencilOp op : ops) {
    for (int path = 0; path < 3; ++path) {
      for (uint32_t initial : {0u, 255u, 0x81u}) {
        Harness h(8, 8);
        Image st(8, 8, 8);  // a D32_S8-like texel: depth float at 0, stencil at byte 4
        for (uint32_t i = 0; i < 64; ++i) {
          const float one = 0.5f;
          std::memcpy(&st.data[i * 8], &one, 4);
          st.data[i * 8 + 4] = uint8_t(initial);
        }
        auto& ds = h.target.depthStencil;
        ds.depthFormat = DepthFormat::D32SFloat;
        ds.depth = st.surface();
        ds.depthTexelBytes = 8;
        ds.stencilFormat = StencilFormat::S8UInt;
        ds.stencil = st.surface();
        ds.stencilTexelBytes = 8;
        ds.stencilOffset = 4;
        h.state.stencilTest = true;
        h.state.depthTest = true;
        h.state.depthCompare = path == 1 ? CompareOp::Never : CompareOp::Always;
        StencilFace& f = h.state.front;
        f.compareOp = path == 0 ? CompareOp::Never : CompareOp::Always;
        f.failOp = f.depthFailOp = f.passOp = StencilOp::Keep;
        (path == 0 ? f.failOp : path == 1 ? f.depthFailOp : f.passOp) = op;
        f.reference = 0x5A;
        f.writeMask = 0xF0;
        h.state.back = f;
        h.state.back.reference = 0x3C;                   // the back face is not used
        h.vertex(0, 0), h.vertex(0, 8), h.vertex(8, 0);  // counter-clockwise: front
        h.run();
        const uint32_t v = apply(op, initial, 0x5A);
        const uint32_t expected = (initial & 0x0F) | (v & 0xF0);
        EXPECT_EQ(st.data[(1 * 8 + 1) * 8 + 4], expected) << int(op) << " path " << path << " init " << initial;
        EXPECT_EQ(h.color.f(1, 1, 3), path == 2 ? 1.0f : 0.0f);
      }
    }
  }
  // compareMask and the back face's reference: back face (clockwise), Equal with (ref & mask) == (stored & mask).
  Harness h(8, 8);
  Image st(8, 8, 1);
  std::fill(st.data.begin(), st.data.end(), uint8_t(0x37));
  h.target.depthStencil.stencilFormat = StencilFormat::S8UInt;
  h.target.depthStencil.stencil = st.surface();
  h.target.depthStencil.stencilTexelBytes = 1;
  h.state.stencilTest = true;
  h.state.back.compareOp = CompareOp::Equal;
  h.state.back.compareMask = 0x0F;
  h.state.back.reference = 0xF7;
  h.state.front.compareOp = CompareOp::Never;
  h.vertex(0, 0), h.vertex(8, 0), h.vertex(0, 8);  // clockwise: back
  h.run();
  EXPECT_EQ(h.color.f(1, 1, 3), 1.0f);
}

double factor(BlendFactor f, int c, const Vec4& s, const Vec4& s1, const Vec4& d, const Vec4& k) {
  using B = BlendFactor;
  switch (f) {
    case B::Zero: return 0;
    case B::One: return 1;
    case B::SrcColor: return s[c];
    case B::OneMinusSrcColor: return 1 - s[c];
    case B::DstColor: return d[c];
    case B::OneMinusDstColor: return 1 - d[c];
    case B::SrcAlpha: return s[3];
    case B::OneMinusSrcAlpha: return 1 - s[3];
    case B::DstAlpha: return d[3];
    case B::OneMinusDstAlpha: return 1 - d[3];
    case B::ConstantColor: return k[c];
    case B::OneMinusConstantColor: return 1 - k[c];
    case B::ConstantAlpha: return k[3];
    case B::OneMinusConstantAlpha: return 1 - k[3];
    case B::SrcAlphaSaturate: return c == 3 ? 1 : std::min(s[3], 1 - d[3]);
    case B::Src1Color: return s1[c];
    case B::OneMinusSrc1Color: return 1 - s1[c];
    case B::Src1Alpha: return s1[3];
    case B::OneMinusSrc1Alpha: return 1 - s1[3];
  }
  return 0;
}

TEST(RasterBlend, EveryFactorAndOp) {
  const Vec4 s = {0.2f, 0.4f, 0.6f, 0.3f}, s1 = {0.9f, 0.7f, 0.1f, 0.45f}, d = {0.5f, 0.25f, 0.125f, 0.75f},
             k = {0.1f, 0.2f, 0.3f, 0.4f};
  for (int f = 0; f <= int(BlendFactor::OneMinusSrc1Alpha); ++f) {
    for (int op = 0; op < 5; ++op) {
      Harness h(8, 8);
      h.constant = s, h.constant1 = s1;
      h.color.fillF(d);
      auto& b = h.state.blend[0];
      b.enable = true;
      b.srcColor = b.srcAlpha = BlendFactor(f);
      b.dstColor = b.dstAlpha = BlendFactor((f + 5) % 19);
      b.colorOp = b.alphaOp = BlendOp(op);
      std::memcpy(h.state.blendConstants, k.data(), 16);
      quad(h, 0.5f);
      h.run();
      for (int c = 0; c < 4; ++c) {
        const double sf = factor(BlendFactor(f), c, s, s1, d, k),
                     df = factor(BlendFactor((f + 5) % 19), c, s, s1, d, k);
        double e = 0;
        switch (BlendOp(op)) {
          case BlendOp::Add: e = s[c] * sf + d[c] * df; break;
          case BlendOp::Subtract: e = s[c] * sf - d[c] * df; break;
          case BlendOp::ReverseSubtract: e = d[c] * df - s[c] * sf; break;
          case BlendOp::Min: e = std::min(s[c], d[c]); break;
          case BlendOp::Max: e = std::max(s[c], d[c]); break;
        }
        ASSERT_NEAR(h.color.f(4, 4, c), e, 1e-6) << "factor " << f << " op " << op << " c " << c;
      }
    }
  }
}

TEST(RasterBlend, UNormClampWriteMaskAndLogicOp) {
  auto unorm = [](Harness& h, Image& img) {
    img = Image(8, 8, 4);
    h.target.colorFormat[0].kind = ColorFormat::Kind::UNorm;
    h.target.colorFormat[0].texelBytes = 4;
    h.target.colorFormat[0].decode = decodeU8;
    h.target.colorFormat[0].encode = encodeU8;
  };
  {
    // Source 1.5 clamps to 1 before blending: 1 * 1 + dst(0.2) * 0 ... with ONE/ONE: 1 + 0.2 -> clamp 1.
    Harness h(8, 8);
    unorm(h, h.color);
    h.constant = {1.5f, -0.5f, 0.25f, 1};
    std::fill(h.color.data.begin(), h.color.data.end(), uint8_t(51));  // 0.2
    h.state.blend[0].enable = true;
    h.state.blend[0].srcColor = h.state.blend[0].dstColor = BlendFactor::One;
    h.state.blend[0].writeMask = 0b0101;  // R and B
    quad(h, 0.5f);
    h.run();
    const uint8_t* p = h.color.at(2, 2);
    EXPECT_EQ(p[0], 255);  // min(1 + 0.2, 1)
    EXPECT_EQ(p[1], 51);   // masked
    EXPECT_EQ(p[2], uint8_t(std::lround((0.25 + 0.2) * 255)));
    EXPECT_EQ(p[3], 51);  // masked
  }
  {
    // Logic op XOR on the texel bits: 1.0 (0xFF) ^ 0x0F = 0xF0; blending is ignored.
    Harness h(8, 8);
    unorm(h, h.color);
    h.constant = {1, 0, 1, 0};
    std::fill(h.color.data.begin(), h.color.data.end(), uint8_t(0x0F));
    h.state.logicOpEnable = true;
    h.state.logicOp = LogicOp::Xor;
    h.state.blend[0].enable = true;
    quad(h, 0.5f);
    h.run();
    const uint8_t* p = h.color.at(2, 2);
    EXPECT_EQ(p[0], 0xF0);
    EXPECT_EQ(p[1], 0x0F);
    EXPECT_EQ(p[2], 0xF0);
    EXPECT_EQ(p[3], 0x0F);
  }
  {
    // Integer formats do not blend.
    Harness h(8, 8);
    h.color = Image(8, 8, 4);
    h.target.colorFormat[0] = ColorFormat{ColorFormat::Kind::UInt, 4, 1, nullptr, decodeU32, encodeU32};
    h.state.blend[0].enable = true;
    h.state.blend[0].srcColor = BlendFactor::Zero;
    h.state.blend[0].dstColor = BlendFactor::One;
    uint32_t word = 1234;
    std::memcpy(h.constant.data(), &word, 4);
    quad(h, 0.5f);
    h.run();
    uint32_t out;
    std::memcpy(&out, h.color.at(3, 3), 4);
    EXPECT_EQ(out, 1234u);
  }
}

TEST(RasterBlend, MultisampledColorPerCoveredSample) {
  // With 4 samples, a fragment writes only its covered samples; a depth test per sample decides them.
  Harness h(8, 8, 4);
  DepthSetup d;
  d.attach(h, DepthFormat::D32SFloat);
  for (uint32_t i = 0; i < 64 * 4; ++i) {
    const float v = (i % 4 == 1) ? 0.0f : 1.0f;  // sample 1 nearer than anything
    std::memcpy(d.depth.data.data() + 4 * i, &v, 4);
  }
  h.state.depthTest = true;
  h.state.depthCompare = CompareOp::Less;
  quad(h, 0.5f);
  h.run();
  EXPECT_EQ(h.color.f(3, 3, 0, 0), 1.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 1), 0.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 2), 1.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 3), 1.0f);
}

}  // namespace
}  // namespace vkrt::raster::test
