// The back end's specialised quad paths (raster/backend.cpp planBackEnd: D32 depth alone and the 8-bit UNorm colour
// layouts with one sample, a whole 2x2 quad at once) against the general per-lane path: the same draws, once with the
// quad paths and once without (setQuadPaths), write the same colour and depth bytes; partly covered quads, quads cut
// by an odd-sized target, failing and passing depth in one quad, every blend factor and op and write masks included.
// And the plan: the states that take a quad path, and those that must not.
#include <gtest/gtest.h>

#include <cmath>

#include "raster/internal.hpp"
#include "raster_harness.hpp"
#include "raster_runtime_codecs.hpp"

namespace vkrt::raster::test {
namespace {

struct Scene {
  ColorFormat::Layout layout = ColorFormat::Layout::RGBA8UNorm;
  VkFormat genericFormat = VK_FORMAT_R8G8B8A8_UNORM;  // with layout Generic: the format the runtime's codecs convert
  bool float16 = false;  // an R16G16B16A16_SFLOAT target instead (8-byte texels, the float16 quad path)
  BlendAttachment blend;
  bool depthTest = false, depthWrite = false;
  CompareOp compare = CompareOp::Less;
  bool depthBounds = false;
  DepthFormat depthFormat = DepthFormat::D32SFloat;
  uint32_t depthTexelBytes = 4;  // D32: 8 is a D32_SFLOAT_S8_UINT-like texel (stencil unused); D16: 2
  uint32_t samples = 1;
  uint32_t seed = 0;  // nonzero: random stored bytes, vertex colours and blend constants from this seed
};

// The Vulkan format of a layout.
VkFormat vkFormatOf(ColorFormat::Layout layout) {
  switch (layout) {
    case ColorFormat::Layout::BGRA8UNorm: return VK_FORMAT_B8G8R8A8_UNORM;
    case ColorFormat::Layout::RGBA8Srgb: return VK_FORMAT_R8G8B8A8_SRGB;
    case ColorFormat::Layout::BGRA8Srgb: return VK_FORMAT_B8G8R8A8_SRGB;
    default: return VK_FORMAT_R8G8B8A8_UNORM;
  }
}

constexpr ColorFormat::Layout kLayouts[] = {ColorFormat::Layout::RGBA8UNorm, ColorFormat::Layout::BGRA8UNorm,
                                            ColorFormat::Layout::RGBA8Srgb, ColorFormat::Layout::BGRA8Srgb};

// Small, seeded, the same on every machine.
struct Rng {
  uint64_t s;
  uint32_t next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return uint32_t(s >> 33);
  }
  // Mostly in [-0.25, 1.25], sometimes exactly 0, 1, -0, 0.5 or a NaN (the clamps' and the encode's edge cases).
  float value() {
    const uint32_t r = next();
    switch (r % 16) {
      case 0: return 0.0f;
      case 1: return 1.0f;
      case 2: return -0.0f;
      case 3: return 0.5f;
      case 4: return r % 64 == 4 ? std::nanf("") : 1.0f / 255;
      default: return -0.25f + 1.5f * float(next() % 1000000) / 1e6f;
    }
  }
};

struct Result {
  std::vector<uint8_t> color, depth;
};

// A 15x13 target (quads cut by its right and bottom edges) holding varied bytes and depths, then five overlapping
// triangles whose colours (interpolated, some components outside [0, 1]) and depths vary per pixel.
Result render(const Scene& sc, bool quadPaths) {
  constexpr uint32_t W = 15, H = 13;
  detail::setQuadPaths(quadPaths);
  Harness h(W, H, sc.samples);
  h.color = Image(W, H, sc.float16 ? 8 : 4, sc.samples);
  Rng rng{sc.seed};
  for (size_t i = 0; i < h.color.data.size(); ++i)
    h.color.data[i] = sc.seed ? uint8_t(rng.next()) : uint8_t(i * 7 + i / 4);
  ColorFormat& f = h.target.colorFormat[0];
  f.kind = sc.float16 ? ColorFormat::Kind::Float : ColorFormat::Kind::UNorm;
  f.texelBytes = sc.float16 ? 8 : 4;
  f.format = formatInfo(sc.float16                                  ? VK_FORMAT_R16G16B16A16_SFLOAT
                        : sc.layout == ColorFormat::Layout::Generic ? sc.genericFormat
                                                                    : vkFormatOf(sc.layout));
  f.rgba16Float = sc.float16;
  f.decode = decodeRuntime;
  f.encode = encodeRuntime;
  f.layout = sc.float16 ? ColorFormat::Layout::Generic : sc.layout;
  Image depth(W, H, sc.depthTexelBytes, sc.samples);
  for (size_t i = 0; i < depth.data.size() / sc.depthTexelBytes; ++i) {
    const uint32_t step = (i * 37) % 101;  // 0..100: stored depths from 0 to 1
    // Every fourth texel within one step of the fourth triangle's depth 0.6 as stored (below, equal, above): the
    // compare ops' edge cases.
    const int near = i % 4 == 0 ? int(i / 4 % 3) - 1 : 2;
    uint8_t* p = depth.data.data() + i * sc.depthTexelBytes;
    if (sc.depthFormat == DepthFormat::D16UNorm) {
      const uint16_t v = uint16_t(near < 2 ? std::lrint(double(0.6f) * 65535) + near : step * 655);
      std::memcpy(p, &v, 2);
    } else if (sc.depthFormat == DepthFormat::X8D24UNorm) {
      const uint32_t d = uint32_t(near < 2 ? std::lrint(double(0.6f) * 16777215) + near : step * 166111);
      const uint32_t v = uint32_t(i * 29 % 256) << 24 | d;  // the top byte varies and must stay
      std::memcpy(p, &v, 4);
    } else {
      const float z = near < 2 ? std::nextafter(0.6f, near < 0 ? 0.0f : near > 0 ? 1.0f : 0.6f) : float(step) / 100;
      std::memcpy(p, &z, 4);
      if (sc.depthTexelBytes == 8) {
        const uint32_t stencilWord = uint32_t(i * 0x9E3779B9u) | 0x7F800001u;  // stencil and padding: must stay
        std::memcpy(p + 4, &stencilWord, 4);                                   // (a signalling NaN's bits, too)
      }
    }
  }
  auto& ds = h.target.depthStencil;
  ds.depthFormat = sc.depthFormat;
  ds.depth = depth.surface();
  ds.depthTexelBytes = sc.depthTexelBytes;
  h.state.depthTest = sc.depthTest;
  h.state.depthWrite = sc.depthWrite;
  h.state.depthCompare = sc.compare;
  h.state.blend[0] = sc.blend;
  const float k[4] = {0.25f, 0.5f, 0.125f, 0.7f};
  std::memcpy(h.state.blendConstants, k, 16);
  h.constant1 = {0.1f, 0.9f, 1.5f, 0.3f};
  if (sc.seed) {
    for (float& c : h.state.blendConstants) c = rng.value();
    for (float& c : h.constant1) c = rng.value();
  }
  h.mode = FragMode::Input0;
  std::vector<Vec4> colors;
  auto tri = [&](float x0, float y0, float z0, float x1, float y1, float z1, float x2, float y2, float z2) {
    h.vertex(x0, y0, z0), h.vertex(x1, y1, z1), h.vertex(x2, y2, z2);
    if (sc.seed) {
      for (int v = 0; v < 3; ++v) colors.push_back({rng.value(), rng.value(), rng.value(), rng.value()});
      return;
    }
    colors.push_back({0.8f, -0.2f, 0.45f, 0.6f});
    colors.push_back({0.1f, 0.7f, 1.3f, 0.2f});
    colors.push_back({0.55f, 0.3f, 0.0f, 0.95f});
  };
  tri(0, 0, 0.1f, 15, 0, 0.9f, 0, 13, 0.5f);  // covers about half, depth crossing the stored values
  tri(15, 0, 0.3f, 15, 13, 0.3f, 0, 13, 0.7f);
  tri(2.3f, 1.7f, 0.2f, 13.6f, 5.1f, 0.4f, 4.2f, 12.4f, 0.8f);  // partly covered quads everywhere along its edges
  tri(0, 0, 0.6f, 15, 0, 0.6f, 15, 13, 0.6f);
  tri(-3, -3, 0.0f, 20, -3, 1.0f, -3, 20, 0.45f);  // past the target: clipped to it
  h.addInput(Interpolation::Smooth, colors);
  h.run();
  detail::setQuadPaths(true);
  return {h.color.data, depth.data};
}

// The general path's bytes against the quad paths', with each copy of the 8-bit UNorm colour writes (baseline and,
// where the CPU has AVX2, the AVX2 one); and the layout's inline codecs against the runtime's (the same draws with
// layout Generic: the format's decode and encode, as for any other format).
void expectSame(const Scene& sc, const char* what) {
  const Result general = render(sc, false);
  if (sc.layout != ColorFormat::Layout::Generic && !sc.float16) {
    Scene g = sc;
    g.layout = ColorFormat::Layout::Generic;
    g.genericFormat = vkFormatOf(sc.layout);
    const Result runtime = render(g, false);
    ASSERT_EQ(general.color, runtime.color) << what << " (the runtime's codecs)";
  }
  const bool before = detail::quadWritesAvx2();
  for (bool avx2 : {false, true}) {
    if (!detail::setQuadWritesAvx2(avx2)) continue;  // no AVX2 on this CPU: the baseline copy is all there is
    const Result quad = render(sc, true);
    const char* copy = avx2 ? " (AVX2 copy)" : " (baseline copy)";
    ASSERT_EQ(general.color, quad.color) << what << copy;
    ASSERT_EQ(general.depth, quad.depth) << what << copy;
  }
  detail::setQuadWritesAvx2(before);
}

// Which paths planBackEnd takes for a state (bit 0 depth/stencil, bit 1 colour attachment 0).
uint32_t planned(const Scene& sc, bool stencilTest = false, bool logicOp = false) {
  uint8_t storage[64] = {};
  Target tg;
  tg.colorCount = 1;
  tg.color[0].base = storage;
  tg.color[0].samples = sc.samples;
  tg.colorFormat[0].layout = sc.float16 ? ColorFormat::Layout::Generic : sc.layout;
  tg.colorFormat[0].rgba16Float = sc.float16;
  tg.colorFormat[0].encode = encodeRuntime;
  tg.colorFormat[0].decode = decodeRuntime;
  tg.samples = sc.samples;
  tg.depthStencil.depthFormat = sc.depthFormat;
  tg.depthStencil.depth.base = storage;
  tg.depthStencil.depth.samples = sc.samples;
  tg.depthStencil.depthTexelBytes = sc.depthTexelBytes;
  tg.depthStencil.stencilFormat = StencilFormat::S8UInt;
  tg.depthStencil.stencil.base = storage;
  State st;
  st.depthTest = sc.depthTest, st.depthWrite = sc.depthWrite, st.depthCompare = sc.compare;
  st.stencilTest = stencilTest;
  st.depthBoundsTest = sc.depthBounds;
  st.logicOpEnable = logicOp;
  st.blend[0] = sc.blend;
  FragmentStage fs;
  fs.outputMask = 1;
  detail::DrawContext ctx{};
  ctx.target = &tg, ctx.state = &st, ctx.fragment = &fs, ctx.samples = sc.samples;
  detail::planBackEnd(ctx);
  return ctx.backEnd.quadPaths;
}

// The colour writes planBackEnd chooses for attachment 0 of a draw in `sc`'s state.
auto plannedColor(const Scene& sc) {
  uint8_t storage[64] = {};
  Target tg;
  tg.colorCount = 1;
  tg.color[0].base = storage;
  tg.color[0].samples = 1;
  tg.colorFormat[0].layout = sc.layout;
  tg.colorFormat[0].encode = encodeRuntime;
  tg.colorFormat[0].decode = decodeRuntime;
  tg.samples = 1;
  State st;
  st.blend[0] = sc.blend;
  FragmentStage fs;
  fs.outputMask = 1;
  detail::DrawContext ctx{};
  ctx.target = &tg, ctx.state = &st, ctx.fragment = &fs, ctx.samples = 1;
  detail::planBackEnd(ctx);
  return ctx.backEnd.color[0];
}

// Where the CPU has AVX2 the two copies are different code (so expectSame compares both with the general path), and
// the setting cannot choose AVX2 where it has none.
TEST(RasterQuadPath, EachCopyOfTheColourWritesIsItsOwn) {
  const bool before = detail::quadWritesAvx2();
  Scene sc;
  sc.blend.enable = true;
  sc.blend.srcColor = BlendFactor::SrcAlpha, sc.blend.dstColor = BlendFactor::OneMinusSrcAlpha;
  ASSERT_TRUE(detail::setQuadWritesAvx2(false));
  const auto baseline = plannedColor(sc);
  ASSERT_NE(baseline, nullptr);
  if (!__builtin_cpu_supports("avx2")) {
    EXPECT_FALSE(detail::setQuadWritesAvx2(true));
    EXPECT_FALSE(detail::quadWritesAvx2());
    GTEST_SKIP() << "no AVX2 on this CPU: only the baseline copy runs here";
  }
  ASSERT_TRUE(detail::setQuadWritesAvx2(true));
  const auto avx2 = plannedColor(sc);
  detail::setQuadWritesAvx2(before);
  EXPECT_NE(avx2, nullptr);
  EXPECT_NE(avx2, baseline);
}

TEST(RasterQuadPath, DepthEveryFormatCompareOpAndWriteAsTheGeneralPath) {
  const std::pair<DepthFormat, uint32_t> formats[] = {{DepthFormat::D32SFloat, 4},
                                                      {DepthFormat::D32SFloat, 8},
                                                      {DepthFormat::D16UNorm, 2},
                                                      {DepthFormat::X8D24UNorm, 4}};
  for (const auto& [format, bytes] : formats) {
    for (int op = 0; op < 8; ++op) {
      for (bool write : {false, true}) {
        Scene sc;
        sc.depthTest = true, sc.depthWrite = write, sc.compare = CompareOp(op);
        sc.depthFormat = format, sc.depthTexelBytes = bytes;
        ASSERT_EQ(planned(sc), 3u);
        expectSame(sc, ("format " + std::to_string(int(format)) + " bytes " + std::to_string(bytes) + " op " +
                        std::to_string(op) + " write " + std::to_string(write))
                           .c_str());
      }
    }
  }
}

constexpr uint32_t kFactors = uint32_t(BlendFactor::OneMinusSrc1Alpha) + 1;

// The blend equations with code of their own (backend.cpp kBlendShapes).
using F = BlendFactor;
constexpr BlendFactor kShapes[][4] = {{F::SrcAlpha, F::OneMinusSrcAlpha, F::One, F::OneMinusSrcAlpha},
                                      {F::SrcAlpha, F::OneMinusSrcAlpha, F::SrcAlpha, F::OneMinusSrcAlpha},
                                      {F::One, F::OneMinusSrcAlpha, F::One, F::OneMinusSrcAlpha},
                                      {F::One, F::One, F::One, F::One}};

// Every factor in each slot and every op (with a depth test, written for odd factors, and varied write masks) into
// `base`'s colour target: the quad paths write the general path's bytes.
void expectEveryFactorAndOp(const Scene& base, const std::string& what) {
  for (uint32_t f = 0; f < kFactors; ++f) {
    for (int op = 0; op < 5; ++op) {
      Scene sc = base;
      sc.depthTest = true, sc.depthWrite = (f & 1) != 0;
      BlendAttachment& b = sc.blend;
      b.enable = true;
      b.srcColor = BlendFactor(f), b.dstColor = BlendFactor((f + 5) % kFactors);
      b.srcAlpha = BlendFactor((f + 3) % kFactors), b.dstAlpha = BlendFactor((f + 11) % kFactors);
      b.colorOp = BlendOp(op), b.alphaOp = BlendOp((op + 2) % 5);
      b.writeMask = f % 3 == 0 ? 0xF : uint8_t(1 + (f + op) % 15);
      ASSERT_EQ(planned(sc), 3u);
      expectSame(sc, (what + "factor " + std::to_string(f) + " op " + std::to_string(op)).c_str());
    }
  }
}

// The blend state of random draw `seed` (`pick` draws the factors and ops): blending off for every eighth, an
// equation with code of its own for every fifth, else every factor and op in each slot at random; a random write
// mask for every third.
void randomBlend(uint32_t seed, Rng& pick, BlendAttachment& b) {
  b.enable = seed % 8 != 0;
  if (seed % 5 == 0) {
    const auto& shape = kShapes[seed / 5 % 4];
    b.srcColor = shape[0], b.dstColor = shape[1], b.srcAlpha = shape[2], b.dstAlpha = shape[3];
  } else {
    b.srcColor = BlendFactor(pick.next() % kFactors), b.dstColor = BlendFactor(pick.next() % kFactors);
    b.srcAlpha = BlendFactor(pick.next() % kFactors), b.dstAlpha = BlendFactor(pick.next() % kFactors);
    b.colorOp = BlendOp(pick.next() % 5), b.alphaOp = BlendOp(pick.next() % 5);
  }
  b.writeMask = seed % 3 == 0 ? uint8_t(1 + pick.next() % 15) : 0xF;
}

TEST(RasterQuadPath, Unorm8EveryBlendFactorOpAndWriteMaskAsTheGeneralPath) {
  for (ColorFormat::Layout layout : kLayouts) {
    Scene base;
    base.layout = layout;
    ASSERT_NO_FATAL_FAILURE(expectEveryFactorAndOp(base, ""));
    // The blend equations with code of their own, and a near miss of them.
    const BlendFactor nearMiss[4] = {F::One, F::One, F::One, F::Zero};
    for (const BlendFactor* shape : {kShapes[0], kShapes[1], kShapes[2], kShapes[3], nearMiss}) {
      for (int op : {0, 1}) {
        for (uint8_t mask : {0xF, 0x7}) {
          Scene sc;
          sc.layout = layout;
          BlendAttachment& b = sc.blend;
          b.enable = true;
          b.srcColor = shape[0], b.dstColor = shape[1], b.srcAlpha = shape[2], b.dstAlpha = shape[3];
          b.colorOp = BlendOp(op), b.alphaOp = BlendOp::Add;
          b.writeMask = mask;
          expectSame(sc, ("shape " + std::to_string(int(shape[0])) + " op " + std::to_string(op)).c_str());
        }
      }
    }
    // Without blending: the whole texel replaced, and a write mask (the destination read back).
    for (uint8_t mask : {0xF, 0x5, 0x8}) {
      Scene sc;
      sc.layout = layout;
      sc.blend.writeMask = mask;
      ASSERT_EQ(planned(sc), 2u);  // no depth test: nothing specialised to do there
      expectSame(sc, ("mask " + std::to_string(mask)).c_str());
    }
  }
}

// Random stored bytes, vertex colours (NaN, -0, exact 0, 0.5 and 1, values outside [0, 1]), blend constants and
// dual-source values, under random blend states (every factor and op in each slot) and each equation with code of its
// own: the quad path writes the general path's bytes.
TEST(RasterQuadPath, Unorm8RandomInputsAsTheGeneralPath) {
  Rng pick{12345};
  for (uint32_t seed = 1; seed <= 400; ++seed) {
    Scene sc;
    sc.seed = seed;
    sc.layout = kLayouts[seed % 4];
    randomBlend(seed, pick, sc.blend);
    ASSERT_EQ(planned(sc), 2u);
    expectSame(sc, ("seed " + std::to_string(seed)).c_str());
  }
}

// R16G16B16A16_SFLOAT (backend.cpp half4Quad, both copies): every blend factor and op in each slot, the equations
// with code of their own, write masks, then random stored halves (NaN, infinities, subnormals), colours, constants
// and blend states: the general path's bytes, which go through the format's codecs.
TEST(RasterQuadPath, Float16EveryBlendAndRandomInputsAsTheGeneralPath) {
  Scene base;
  base.float16 = true;
  ASSERT_NO_FATAL_FAILURE(expectEveryFactorAndOp(base, "float16 "));
  Rng pick{777};
  for (uint32_t seed = 1; seed <= 200; ++seed) {
    Scene sc;
    sc.float16 = true;
    sc.seed = seed;
    randomBlend(seed, pick, sc.blend);
    ASSERT_EQ(planned(sc), 2u);
    expectSame(sc, ("float16 seed " + std::to_string(seed)).c_str());
  }
}

// The quad paths against values computed here: src-alpha blending over stored bytes, a depth test that passes and
// writes on one half and fails on the other.
TEST(RasterQuadPath, WritesTheFormulasValues) {
  Harness h(8, 8);
  h.color = Image(8, 8, 4);
  std::fill(h.color.data.begin(), h.color.data.end(), uint8_t(100));
  ColorFormat& f = h.target.colorFormat[0];
  f.kind = ColorFormat::Kind::UNorm;
  f.texelBytes = 4;
  f.format = formatInfo(VK_FORMAT_R8G8B8A8_UNORM);
  f.decode = decodeRuntime, f.encode = encodeRuntime;
  f.layout = ColorFormat::Layout::RGBA8UNorm;
  Image depth(8, 8, 4);
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      const float z = x < 4 ? 0.5f : 0.1f;
      std::memcpy(depth.at(x, y), &z, 4);
    }
  h.target.depthStencil.depthFormat = DepthFormat::D32SFloat;
  h.target.depthStencil.depth = depth.surface();
  h.target.depthStencil.depthTexelBytes = 4;
  h.state.depthTest = h.state.depthWrite = true;
  h.state.depthCompare = CompareOp::Less;
  BlendAttachment& b = h.state.blend[0];
  b.enable = true;
  b.srcColor = BlendFactor::SrcAlpha, b.dstColor = BlendFactor::OneMinusSrcAlpha;
  b.srcAlpha = BlendFactor::One, b.dstAlpha = BlendFactor::Zero;
  h.constant = {0.5f, 0.25f, 1.5f, 0.2f};
  h.vertex(0, 0, 0.25f), h.vertex(8, 0, 0.25f), h.vertex(0, 8, 0.25f);
  h.vertex(8, 0, 0.25f), h.vertex(8, 8, 0.25f), h.vertex(0, 8, 0.25f);
  h.run();
  const double d = 100.0 / 255;
  const uint8_t blended[4] = {uint8_t(std::lround((0.5 * 0.2 + d * 0.8) * 255)),
                              uint8_t(std::lround((0.25 * 0.2 + d * 0.8) * 255)),
                              uint8_t(std::lround((1.0 * 0.2 + d * 0.8) * 255)), uint8_t(std::lround(0.2 * 255))};
  for (uint32_t y = 0; y < 8; ++y)
    for (uint32_t x = 0; x < 8; ++x) {
      float z;
      std::memcpy(&z, depth.at(x, y), 4);
      for (int c = 0; c < 4; ++c) ASSERT_EQ(h.color.at(x, y)[c], x < 4 ? blended[c] : 100) << x << "," << y << " " << c;
      ASSERT_EQ(z, x < 4 ? 0.25f : 0.1f) << x << "," << y;
    }
}

// The tile loop's two copies (raster/tile_kernels.inc, compiled for the baseline target and for AVX2): triangles at
// varied depths and clip w, inputs of each interpolation (Smooth, NoPerspective, Flat, centroid), one and four
// samples, a depth test that writes: the AVX2 copy writes the baseline copy's colour and depth bytes.
TEST(RasterQuadPath, TheTileLoopsAvx2CopyWritesTheBaselineCopysBytes) {
  if (!__builtin_cpu_supports("avx2")) GTEST_SKIP() << "no AVX2 on this CPU: only the baseline copy runs here";
  const bool before = detail::quadWritesAvx2();
  for (uint32_t samples : {1u, 4u}) {
    for (uint32_t slot = 0; slot < 4; ++slot) {
      Result result[2];
      for (bool avx2 : {false, true}) {
        ASSERT_TRUE(detail::setQuadWritesAvx2(avx2));
        constexpr uint32_t W = 37, H = 29;
        Harness h(W, H, samples);
        Image depth(W, H, 4, samples);
        const float far = 1.0f;
        for (size_t i = 0; i < depth.data.size(); i += 4) std::memcpy(&depth.data[i], &far, 4);
        auto& ds = h.target.depthStencil;
        ds.depthFormat = DepthFormat::D32SFloat;
        ds.depth = depth.surface();
        ds.depthTexelBytes = 4;
        h.state.depthTest = h.state.depthWrite = true;
        h.state.depthCompare = CompareOp::Less;
        h.mode = FragMode::Input0;
        h.inputSlot = slot;
        Rng rng{77 + slot};
        std::vector<Vec4> in[4];
        for (int t = 0; t < 12; ++t) {
          for (int v = 0; v < 3; ++v) {
            const float x = -4.0f + 45.0f * float(rng.next() % 1000) / 1000,
                        y = -4.0f + 37.0f * float(rng.next() % 1000) / 1000;
            const float z = float(rng.next() % 1000) / 1000, w = 0.25f + 3.0f * float(rng.next() % 1000) / 1000;
            h.vertex(x, y, z, w);
            for (auto& values : in) values.push_back({rng.value(), rng.value(), rng.value(), rng.value()});
          }
        }
        h.addInput(Interpolation::Smooth, in[0]);
        h.addInput(Interpolation::NoPerspective, in[1]);
        h.addInput(Interpolation::Flat, in[2]);
        h.addInput(Interpolation::Smooth, in[3], true);  // centroid
        h.run();
        result[avx2] = {h.color.data, depth.data};
      }
      EXPECT_EQ(result[0].color, result[1].color) << "samples " << samples << " input " << slot;
      EXPECT_EQ(result[0].depth, result[1].depth) << "samples " << samples << " input " << slot;
    }
  }
  detail::setQuadWritesAvx2(before);
}

TEST(RasterQuadPath, StatesThatMustTakeTheGeneralPath) {
  Scene sc;
  sc.depthTest = true;
  EXPECT_EQ(planned(sc), 3u);
  EXPECT_EQ(planned(sc, true) & 1, 0u);  // stencil
  Scene bounds = sc;
  bounds.depthBounds = true;
  EXPECT_EQ(planned(bounds) & 1, 0u);           // depth bounds
  EXPECT_EQ(planned(sc, false, true) & 2, 0u);  // logic op
  Scene ms = sc;
  ms.samples = 4;
  EXPECT_EQ(planned(ms), 0u);  // 4 samples
  Scene generic = sc;
  generic.layout = ColorFormat::Layout::Generic;
  EXPECT_EQ(planned(generic), 1u);  // any other colour format
  detail::setQuadPaths(false);
  EXPECT_EQ(planned(sc), 0u);  // turned off
  detail::setQuadPaths(true);
  // And those draws write what the quad paths would (with 4 samples the general path is all there is).
  ms.blend.enable = true;
  ms.blend.srcColor = BlendFactor::SrcAlpha, ms.blend.dstColor = BlendFactor::OneMinusSrcAlpha;
  expectSame(ms, "4 samples");
}

}  // namespace
}  // namespace vkrt::raster::test
