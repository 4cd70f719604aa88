// A fragment shader's SPMD entry compiled with an abi::ColorMerge writes colour attachment 0 itself (the back end's
// 8-bit UNorm quad writes, compiled into the shader): every format, blend equation and write mask it takes, over
// random colours (components outside [0, 1], signed zeros, NaN) and random destination bytes, against the writes
// computed here one component at a time from the formulas of "Blend Operations" and the UNorm conversion; only where
// the executor gives it the quad's address; and the shaders it must not merge (discard, FragDepth, integer output).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "gfx_builtins.frag.spv.h"
#include "gfx_color_merge.frag.spv.h"
#include "gfx_color_merge_uint.frag.spv.h"
#include "gfx_spmd_discard.frag.spv.h"
#include "runtime/image_functions.hpp"
#include "spirv/compiler.hpp"

namespace vkrt::testing {
namespace {

using abi::ColorMerge;
using abi::GraphicsInvocation;
using abi::kGraphicsLocations;

template <size_t N>
std::shared_ptr<spirv::CompiledShader> compileMerged(const uint32_t (&words)[N], ColorMerge merge, std::string* error) {
  struct Setting {
    bool was = spirv::spmdEnabled();
    ~Setting() { spirv::setSpmd(was); }
  } setting;
  spirv::setSpmd(true);
  spirv::CompileRequest r;
  r.words = words;
  r.wordCount = N;
  r.model = spv::ExecutionModelFragment;
  r.hostSymbols = imageFunctionSymbols();
  r.colorMerge = merge;
  return spirv::compile(r, error);
}

// Small, seeded, the same on every machine.
struct Rng {
  uint64_t s;
  uint32_t next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return uint32_t(s >> 33);
  }
  // Mostly in [-0.25, 1.25], sometimes exactly 0, 1, -0, 0.5, 1/255, a NaN or an infinity.
  float value() {
    const uint32_t r = next();
    switch (r % 20) {
      case 0: return 0.0f;
      case 1: return 1.0f;
      case 2: return -0.0f;
      case 3: return 0.5f;
      case 4: return 1.0f / 255;
      case 5: return std::nanf("");
      case 6: return r % 40 == 6 ? INFINITY : -INFINITY;
      default: return -0.25f + 1.5f * float(next() % 1000000) / 1e6f;
    }
  }
};

// The reference, one component at a time (the build targets baseline x86-64: no FMA, nothing contracted). clamp01
// keeps a NaN ("the source ... clamped to [0, 1]" where it blends), the conversion to UNorm makes it 0.
float clamp01(float v) {
  const float t = v < 0.0f ? 0.0f : v;
  return 1.0f < t ? 1.0f : t;
}
uint32_t toUnorm8(float v) {
  float t = v > 0.0f ? v : 0.0f;
  t = t < 1.0f ? t : 1.0f;
  return uint32_t(std::nearbyint(t * 255.0f));  // round to nearest even
}

uint32_t expectedTexel(const ColorMerge& m, const float src[4], uint32_t dstTexel) {
  const bool bgra = m.format == ColorMerge::kBgra8Unorm;
  auto shiftOf = [&](int c) { return 8 * (bgra && c != 1 && c != 3 ? 2 - c : c); };
  float s[4], d[4], r[4];
  for (int c = 0; c < 4; ++c) {
    s[c] = m.blend != ColorMerge::kOff ? clamp01(src[c]) : src[c];
    d[c] = float(dstTexel >> shiftOf(c) & 0xFF) / 255.0f;
  }
  for (int c = 0; c < 4; ++c) {
    float sf = 1.0f, df = 1.0f;  // kAdditive: ONE, ONE
    switch (m.blend) {
      case ColorMerge::kOver: sf = c == 3 ? 1.0f : s[3], df = 1.0f - s[3]; break;
      case ColorMerge::kOverAll: sf = s[3], df = 1.0f - s[3]; break;
      case ColorMerge::kPremultiplied: df = 1.0f - s[3]; break;
      default: break;
    }
    const float a = s[c] * sf, b = d[c] * df;
    r[c] = m.blend == ColorMerge::kOff ? s[c] : a + b;
  }
  uint32_t out = 0;
  for (int c = 0; c < 4; ++c) out |= toUnorm8(m.writeMask >> c & 1 ? r[c] : d[c]) << shiftOf(c);
  return out;
}

// Runs the SPMD entry on one quad with colours `color[l][c]`, colorQuad at `dst` (null: none) with row pitch `pitch`.
void runQuad(const spirv::CompiledShader& s, const float color[4][4], uint8_t* dst, int64_t pitch) {
  GraphicsInvocation inv[4] = {};
  alignas(16) uint32_t in[kGraphicsLocations * 4][4] = {}, out[kGraphicsLocations * 4][4] = {}, out1[4][4] = {};
  alignas(16) float fragCoord[4][4] = {};
  alignas(16) uint32_t coverage[4] = {1, 1, 1, 1};
  alignas(16) uint8_t push[abi::kPushConstantBytes] = {}, sink[abi::kSinkBytes] = {};
  for (uint32_t l = 0; l < 4; ++l)
    for (uint32_t c = 0; c < 4; ++c) std::memcpy(&in[c][l], &color[l][c], 4);
  for (uint32_t l = 0; l < 4; ++l) {
    inv[l].base.pushConstants = push;
    inv[l].base.sink = sink;
    inv[l].fragCoordSoa = &fragCoord[0][0];
    inv[l].coverageSoa = coverage;
    inv[l].sampleMaskOut = ~0u;
  }
  inv[0].inputs = &in[0][0];
  inv[0].outputs = &out[0][0];
  inv[0].outputs1 = &out1[0][0];
  inv[0].colorQuad = dst;
  inv[0].colorPitch = pitch;
  s.graphicsEntry(inv);
  // The outputs are written as without the merge (the back end reads them where it writes the quad itself).
  for (uint32_t l = 0; l < 4; ++l)
    for (uint32_t c = 0; c < 4; ++c) {
      uint32_t want;
      std::memcpy(&want, &color[l][c], 4);
      EXPECT_EQ(out[c][l], want) << "lane " << l << " component " << c;
    }
}

TEST(ColorMerge, EveryFormatBlendAndWriteMaskWritesTheFormulasBytes) {
  const ColorMerge::Blend blends[] = {ColorMerge::kOff, ColorMerge::kOver, ColorMerge::kOverAll,
                                      ColorMerge::kPremultiplied, ColorMerge::kAdditive};
  const uint8_t masks[] = {0xF, 0x7, 0xA, 0x1, 0x0};
  int cases = 0;
  for (ColorMerge::Format format : {ColorMerge::kRgba8Unorm, ColorMerge::kBgra8Unorm})
    for (ColorMerge::Blend blend : blends)
      for (uint8_t mask : masks) {
        const ColorMerge m{format, blend, mask};
        std::string error;
        auto s = compileMerged(kSpv_gfx_color_merge_frag, m, &error);
        ASSERT_TRUE(s) << error;
        if (s->spmdLanes != 4) GTEST_SKIP() << "no SPMD fragment entry on this target";
        EXPECT_TRUE(s->graphics.mergesColor);
        // A 2x2 quad at texel (3, 1) of a 7-texel-wide target (pitch 28 + 4 bytes of padding): the texels around
        // it must stay.
        constexpr int64_t kPitch = 32;
        Rng rng{uint64_t(format) * 1000 + uint64_t(blend) * 37 + mask};
        for (int round = 0; round < 64; ++round, ++cases) {
          std::vector<uint8_t> target(kPitch * 4);
          for (uint8_t& byte : target) byte = uint8_t(rng.next());
          const std::vector<uint8_t> before = target;
          float color[4][4];
          for (auto& lane : color)
            for (float& c : lane) c = rng.value();
          uint8_t* quad = target.data() + kPitch + 3 * 4;
          runQuad(*s, color, quad, kPitch);
          std::vector<uint8_t> want = before;
          for (uint32_t l = 0; l < 4; ++l) {
            const size_t at = size_t(kPitch) * (1 + (l >> 1)) + 4 * (3 + (l & 1));
            uint32_t dst;
            std::memcpy(&dst, before.data() + at, 4);
            const uint32_t texel = expectedTexel(m, color[l], dst);
            std::memcpy(want.data() + at, &texel, 4);
          }
          ASSERT_EQ(target, want) << "format " << int(format) << " blend " << int(blend) << " mask " << int(mask)
                                  << " round " << round;
          // Without an address the entry writes nothing.
          runQuad(*s, color, nullptr, kPitch);
          EXPECT_EQ(target, want);
        }
      }
  EXPECT_EQ(cases, 2 * 5 * 5 * 64);
}

TEST(ColorMerge, ShadersTheBackEndMustFinishAreNotMerged) {
  const ColorMerge m{ColorMerge::kRgba8Unorm, ColorMerge::kOver, 0xF};
  std::string error;
  auto plain = compileMerged(kSpv_gfx_color_merge_frag, m, &error);
  ASSERT_TRUE(plain) << error;
  if (plain->spmdLanes != 4) GTEST_SKIP() << "no SPMD fragment entry on this target";
  EXPECT_TRUE(plain->graphics.mergesColor);
  // Without a ColorMerge, nothing is merged.
  auto none = compileMerged(kSpv_gfx_color_merge_frag, ColorMerge{}, &error);
  ASSERT_TRUE(none) << error;
  EXPECT_FALSE(none->graphics.mergesColor);
  // Discard (the back end's tests of the killed lanes), FragDepth (late tests), an integer output.
  auto discard = compileMerged(kSpv_gfx_spmd_discard_frag, m, &error);
  ASSERT_TRUE(discard) << error;
  EXPECT_EQ(discard->spmdLanes, 4);
  EXPECT_TRUE(discard->graphics.canDiscard);
  EXPECT_FALSE(discard->graphics.mergesColor);
  auto depth = compileMerged(kSpv_gfx_builtins_frag, m, &error);
  ASSERT_TRUE(depth) << error;
  EXPECT_TRUE(depth->graphics.writesDepth);
  EXPECT_FALSE(depth->graphics.mergesColor);
  auto integer = compileMerged(kSpv_gfx_color_merge_uint_frag, m, &error);
  ASSERT_TRUE(integer) << error;
  EXPECT_EQ(integer->spmdLanes, 4);
  EXPECT_FALSE(integer->graphics.mergesColor);
}

}  // namespace
}  // namespace vkrt::testing
