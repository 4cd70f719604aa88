// Coverage: the top-left rule against an independent exact reference, shared edges and fans written once,
// sub-pixel snapping, 4 samples, scissor and render area, draw order across tiles.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "raster_harness.hpp"

namespace vkrt::raster::test {
namespace {

constexpr int32_t kSampleX[4] = {96, 224, 32, 160}, kSampleY[4] = {32, 96, 160, 224};

// Draws the triangles (framebuffer coordinates in 1/256 pixel) counting writes per sample, and compares every
// sample with the reference rule summed over the triangles.
void checkAgainstReference(const std::vector<std::array<int64_t, 6>>& tris, uint32_t samples, uint32_t size = 64) {
  Harness h(size, size, samples);
  countWrites(h);
  for (const auto& t : tris)
    for (int i = 0; i < 3; ++i) h.vertex(float(t[2 * i]) / 256, float(t[2 * i + 1]) / 256);
  h.run();
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      for (uint32_t s = 0; s < samples; ++s) {
        const int64_t px = int64_t(x) * 256 + (samples == 1 ? 128 : kSampleX[s]);
        const int64_t py = int64_t(y) * 256 + (samples == 1 ? 128 : kSampleY[s]);
        int expected = 0;
        for (const auto& t : tris) {
          const int64_t X[3] = {t[0], t[2], t[4]}, Y[3] = {t[1], t[3], t[5]};
          expected += referenceCovered(X, Y, px, py);
        }
        ASSERT_EQ(h.color.f(x, y, 0, s), float(expected)) << "pixel " << x << "," << y << " sample " << s;
      }
    }
  }
}

TEST(RasterCoverage, RandomTrianglesMatchTheReference) {
  std::mt19937 rng(7);
  // Coordinates on the sub-pixel grid, many of them on pixel centres and sample rows so that edges pass through
  // samples exactly.
  std::uniform_int_distribution<int> coarse(0, 64 * 2), fine(0, 64 * 256);
  for (uint32_t samples : {1u, 4u}) {
    std::vector<std::array<int64_t, 6>> tris;
    for (int i = 0; i < 40; ++i) {
      std::array<int64_t, 6> t;
      for (auto& c : t) c = (i % 2) ? fine(rng) : coarse(rng) * 128;
      tris.push_back(t);
    }
    checkAgainstReference(tris, samples);
  }
}

// The block path (8x8 blocks: whole blocks inside every edge emitted without a test, the others as bit masks of
// 32-bit edge values, 64-bit lane by lane once an edge is 4096 pixels or longer) against the per-sample reference,
// bit for bit: tiny, medium and huge triangles (edges on both sides of the 32-bit limit), vertices on the sample
// and pixel-centre grid so that edges pass through samples, 1 and 4 samples, a scissor per batch over 2x2 tiles.
TEST(RasterCoverage, BlocksMatchThePerSampleReference) {
  std::mt19937 rng(2026);
  constexpr uint32_t kSize = 128;
  auto uni = [&](int64_t lo, int64_t hi) { return std::uniform_int_distribution<int64_t>(lo, hi)(rng); };
  for (uint32_t samples : {1u, 4u}) {
    for (int batch = 0; batch < 8; ++batch) {
      std::vector<std::array<int64_t, 6>> tris;
      for (int i = 0; i < 24; ++i) {
        std::array<int64_t, 6> t;
        const int kind = (batch + i) % 5;
        // Units: 1/256 pixel. A grid of 32 puts vertices on sample rows/columns and pixel centres.
        const int64_t cx = uni(-8, kSize + 8) * 256, cy = uni(-8, kSize + 8) * 256;
        for (int v = 0; v < 3; ++v) {
          int64_t& x = t[2 * v];
          int64_t& y = t[2 * v + 1];
          if (kind == 0) {  // tiny, within a few pixels, on the 1/256 grid
            x = cx + uni(-600, 600), y = cy + uni(-600, 600);
          } else if (kind == 1) {  // medium, edges through samples
            x = uni(-16, 4 * kSize + 16) * 32 * 2, y = uni(-16, 4 * kSize + 16) * 32 * 2;
          } else if (kind == 2) {  // huge: up to +-20000 pixels (1/16 pixel grid keeps the clip coordinates exact)
            x = uni(-20000 * 16, 20000 * 16) * 16, y = uni(-20000 * 16, 20000 * 16) * 16;
          } else if (kind == 3) {  // long thin edges near 4096 pixels (|dx| + |dy| around 2^20 fixed-point units)
            const int64_t len = (4096 + uni(-2, 2)) * 256 + uni(-40, 40) * 16;
            const int64_t dx = uni(0, len / 16) * 16;
            x = v == 0 ? cx : v == 1 ? cx + dx : cx + uni(-64, 64) * 32;
            y = v == 0 ? cy : v == 1 ? cy - (len - dx) : cy + uni(-64, 64) * 32;
          }
        }
        if (kind == 4) {
          // Huge, with a horizontal, vertical or 45-degree edge through a sample row/column (or the pixel centres)
          // on screen: samples lie exactly on an edge too long for 32-bit block values.
          const int64_t off[5] = {128, 32, 96, 160, 224};
          const int64_t x0 = uni(0, kSize - 1) * 256 + off[uni(0, 4)], y0 = uni(0, kSize - 1) * 256 + off[uni(0, 4)];
          const int64_t len = uni(2048, 5000) * 256, dir = uni(0, 3), sign = uni(0, 1) ? 1 : -1;
          const int64_t dx = dir == 1 ? 0 : sign * len, dy = dir == 0 ? 0 : dir == 3 ? -sign * len : sign * len;
          // The third vertex far away, or 16 to 64 pixels off the edge's middle (then all three edges are long,
          // near the 32-bit limit, and blocks straddling them hold values past +-2^31 a few rows from the edge).
          const bool far = uni(0, 1);
          auto near = [&](int64_t c) { return c + (uni(0, 1) ? 1 : -1) * uni(16 * 32, 64 * 32) * 8; };
          const int64_t x2 = far ? uni(-10000, 10000) * 256 : near(x0);
          const int64_t y2 = far ? uni(-10000, 10000) * 256 : near(y0);
          t = {x0 - dx, y0 - dy, x0 + dx, y0 + dy, x2, y2};
        }
        tris.push_back(t);
      }
      const int32_t sx0 = int32_t(uni(0, kSize / 2)), sy0 = int32_t(uni(0, kSize / 2));
      const Rect scissor{sx0, sy0, uint32_t(uni(1, kSize - sx0)), uint32_t(uni(1, kSize - sy0))};
      Harness h(kSize, kSize, samples);
      countWrites(h);
      h.state.scissors[0] = scissor;
      for (const auto& t : tris)
        for (int i = 0; i < 3; ++i) h.vertex(float(t[2 * i]) / 256, float(t[2 * i + 1]) / 256);
      h.run();
      for (uint32_t y = 0; y < kSize; ++y)
        for (uint32_t x = 0; x < kSize; ++x)
          for (uint32_t s = 0; s < samples; ++s) {
            const bool inScissor = int32_t(x) >= scissor.x && int32_t(x) < scissor.x + int32_t(scissor.width) &&
                                   int32_t(y) >= scissor.y && int32_t(y) < scissor.y + int32_t(scissor.height);
            const int64_t px = int64_t(x) * 256 + (samples == 1 ? 128 : kSampleX[s]);
            const int64_t py = int64_t(y) * 256 + (samples == 1 ? 128 : kSampleY[s]);
            int expected = 0;
            for (const auto& t : tris) {
              const int64_t X[3] = {t[0], t[2], t[4]}, Y[3] = {t[1], t[3], t[5]};
              expected += inScissor && referenceCovered(X, Y, px, py);
            }
            ASSERT_EQ(h.color.f(x, y, 0, s), float(expected))
                << "samples " << samples << " batch " << batch << " pixel " << x << "," << y << " sample " << s;
          }
    }
  }
}

TEST(RasterCoverage, SharedEdgesAreWrittenOnce) {
  // A square split along its diagonal (both windings), and a fan of 8 triangles around a point on a pixel centre.
  const int64_t a = 3 * 256 + 128, b = 40 * 256 + 128;
  std::vector<std::array<int64_t, 6>> tris = {{a, a, b, a, b, b}, {a, a, a, b, b, b}};
  checkAgainstReference(tris, 1);
  checkAgainstReference(tris, 4);
  std::vector<std::array<int64_t, 6>> fan;
  const int64_t cx = 32 * 256 + 128, cy = 32 * 256 + 128;
  const int64_t ring[8][2] = {{cx + 5000, cy}, {cx + 3000, cy + 3000}, {cx, cy + 5000}, {cx - 3000, cy + 3000},
                              {cx - 5000, cy}, {cx - 3000, cy - 3000}, {cx, cy - 5000}, {cx + 3000, cy - 3000}};
  for (int i = 0; i < 8; ++i) {
    const int j = (i + 1) % 8;
    fan.push_back({cx, cy, ring[i][0], ring[i][1], ring[j][0], ring[j][1]});
  }
  for (uint32_t samples : {1u, 4u}) {
    checkAgainstReference(fan, samples);
    // and no sample inside the octagon is written twice or missed
    Harness h(64, 64, samples);
    countWrites(h);
    for (const auto& t : fan)
      for (int i = 0; i < 3; ++i) h.vertex(float(t[2 * i]) / 256, float(t[2 * i + 1]) / 256);
    h.run();
    for (uint32_t s = 0; s < samples; ++s) EXPECT_LE(h.color.f(32, 32, 0, s), 1.0f);
    EXPECT_EQ(h.color.f(32, 32, 0, 0), 1.0f);
  }
}

TEST(RasterCoverage, VerticesSnapToTheSubPixelGrid) {
  // 1/1024 pixel off the grid snaps back: the same samples as the triangle on the grid.
  Harness exact, off;
  countWrites(exact);
  countWrites(off);
  exact.vertex(10.5f, 10.5f), exact.vertex(20.5f, 10.5f), exact.vertex(10.5f, 20.5f);
  off.vertex(10.5f + 1.0f / 1024, 10.5f - 1.0f / 1024), off.vertex(20.5f + 1.0f / 1024, 10.5f);
  off.vertex(10.5f, 20.5f - 1.0f / 1024);
  exact.run();
  off.run();
  EXPECT_EQ(exact.color.data, off.color.data);
  // Pixel (10, 10)'s centre is the top-left corner: on a top and a left edge, covered; (20, 10) is on the
  // hypotenuse's end, not covered.
  EXPECT_EQ(exact.color.f(10, 10), 1.0f);
  EXPECT_EQ(exact.color.f(20, 10), 0.0f);
}

TEST(RasterCoverage, ScissorAndRenderAreaLimitCoverage) {
  Harness h;
  countWrites(h);
  h.state.scissors[0] = Rect{5, 6, 20, 30};
  h.target.renderArea = Rect{10, 0, 50, 30};
  h.vertex(0, 0), h.vertex(64, 0), h.vertex(0, 64);
  h.vertex(64, 0), h.vertex(64, 64), h.vertex(0, 64);
  h.run();
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      const bool inside = x >= 10 && x < 25 && y >= 6 && y < 30;
      ASSERT_EQ(h.color.f(x, y), inside ? 1.0f : 0.0f) << x << "," << y;
    }
}

TEST(RasterCoverage, LaterTrianglesWinAcrossTiles) {
  // 200 overlapping full-screen-ish triangles over 3x3 tiles, each writing its index: every pixel holds the last
  // triangle covering it.
  Harness h(160, 160);
  h.mode = FragMode::Input0;
  std::vector<Vec4> values;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-20.0f, 180.0f);
  std::vector<std::array<float, 6>> tris;
  for (int i = 0; i < 200; ++i) {
    std::array<float, 6> t;
    for (auto& c : t) c = std::round(u(rng) * 256) / 256;
    tris.push_back(t);
    for (int k = 0; k < 3; ++k) h.vertex(t[2 * k], t[2 * k + 1]), values.push_back(Vec4{float(i), 0, 0, 1});
  }
  h.addInput(Interpolation::Flat, values);
  h.color.fillF({-1, 0, 0, 0});
  h.run();
  for (uint32_t y = 0; y < 160; y += 3)
    for (uint32_t x = 0; x < 160; x += 3) {
      float expected = -1;
      for (int i = 0; i < 200; ++i) {
        int64_t X[3], Y[3];
        for (int k = 0; k < 3; ++k)
          X[k] = std::llround(tris[i][2 * k] * 256), Y[k] = std::llround(tris[i][2 * k + 1] * 256);
        if (referenceCovered(X, Y, int64_t(x) * 256 + 128, int64_t(y) * 256 + 128)) expected = float(i);
      }
      ASSERT_EQ(h.color.f(x, y), expected) << x << "," << y;
    }
}

TEST(RasterCoverage, FourSamplesHalfCoveredPixel) {
  // A vertical edge at x = 10.5: samples 0 and 2 (x 0.375, 0.125) of pixel 10 are left of it, 1 and 3 right.
  Harness h(16, 16, 4);
  countWrites(h);
  h.vertex(10.5f, 0), h.vertex(10.5f, 16), h.vertex(0, 0);
  h.run();
  EXPECT_EQ(h.color.f(10, 5, 0, 0), 1.0f);
  EXPECT_EQ(h.color.f(10, 5, 0, 1), 0.0f);
  EXPECT_EQ(h.color.f(10, 5, 0, 2), 1.0f);
  EXPECT_EQ(h.color.f(10, 5, 0, 3), 0.0f);
  for (uint32_t s = 0; s < 4; ++s) EXPECT_EQ(h.color.f(11, 5, 0, s), 0.0f);
}

TEST(RasterCoverage, SampleMaskAndAlphaToCoverage) {
  Harness h(8, 8, 4);
  countWrites(h);
  h.state.sampleMask = 0b1011;
  h.vertex(0, 0), h.vertex(8, 0), h.vertex(0, 8);
  h.vertex(8, 0), h.vertex(8, 8), h.vertex(0, 8);
  h.run();
  EXPECT_EQ(h.color.f(3, 3, 0, 0), 1.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 1), 1.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 2), 0.0f);
  EXPECT_EQ(h.color.f(3, 3, 0, 3), 1.0f);

  Harness a(8, 8, 4);
  a.state.alphaToCoverage = true;
  a.alpha0 = 0.5f;  // two of four samples
  a.constant = {1, 0, 0, 0};
  a.fs.canDiscard = false;
  a.vertex(0, 0), a.vertex(8, 0), a.vertex(0, 8);
  a.vertex(8, 0), a.vertex(8, 8), a.vertex(0, 8);
  a.run();
  int written = 0;
  for (uint32_t s = 0; s < 4; ++s) written += a.color.f(2, 2, 0, s) == 1.0f;
  EXPECT_EQ(written, 2);
  // Alpha 0: nothing written.
  Harness z(8, 8, 4);
  z.state.alphaToCoverage = true;
  z.alpha0 = 0;
  z.vertex(0, 0), z.vertex(8, 0), z.vertex(0, 8);
  z.run();
  for (uint32_t s = 0; s < 4; ++s) EXPECT_EQ(z.color.f(1, 1, 0, s), 0.0f);
}

TEST(RasterCoverage, HelperLanesRunOnlyWhenNeeded) {
  // One triangle covering only pixel (0, 0)'s centre within quad (0, 0); input 0 = x_f (linear), so a helper
  // lane's input is its pixel centre's x.
  for (bool helpers : {false, true}) {
    Harness h(8, 8);
    h.fs.needsHelpers = helpers;
    h.mode = FragMode::Input0;
    h.vertex(0, 0), h.vertex(1.5f, 0), h.vertex(0, 1.5f);
    h.addInput(Interpolation::NoPerspective, {{0, 0, 0, 1}, {1.5f, 0, 0, 1}, {0, 0, 0, 1}});
    h.run();
    EXPECT_EQ(h.color.f(0, 0), 0.5f);
    EXPECT_EQ(h.color.f(1, 0), 0.0f);
    ASSERT_EQ(h.helperRuns.size(), helpers ? 3u : 0u);
    for (size_t i = 0; i < h.helperRuns.size(); ++i)
      EXPECT_FLOAT_EQ(h.helperValues[i], float(h.helperRuns[i] % 8) + 0.5f);
  }
}

}  // namespace
}  // namespace vkrt::raster::test

namespace vkrt::raster::test {
namespace {

TEST(RasterMultisample, CentroidAndPerSampleInterpolation) {
  // Input 0 = x_f (linear). Pixel 10 is half covered (samples 0 and 2, left of x = 10.5).
  for (bool centroid : {false, true}) {
    Harness h(16, 16, 4);
    h.mode = FragMode::Input0;
    h.vertex(10.5f, 0), h.vertex(10.5f, 16), h.vertex(0, 0);
    h.addInput(Interpolation::NoPerspective, {{10.5f, 0, 0, 1}, {10.5f, 0, 0, 1}, {0, 0, 0, 1}}, centroid);
    h.run();
    EXPECT_EQ(h.color.f(10, 12, 0, 0), centroid ? 10.375f : 10.5f);
    EXPECT_EQ(h.color.f(10, 12, 0, 2), centroid ? 10.375f : 10.5f);
    EXPECT_EQ(h.color.f(9, 12, 0, 1), 9.5f);  // fully covered: the centre either way
  }
  // Sample shading: each sample shaded at its own position.
  Harness s(16, 16, 4);
  s.mode = FragMode::Input0;
  s.state.sampleShading = true;
  s.vertex(0, 0), s.vertex(16, 0), s.vertex(0, 16);
  s.addInput(Interpolation::NoPerspective, {{0, 0, 0, 1}, {16, 0, 0, 1}, {0, 0, 0, 1}});
  s.run();
  const float sx[4] = {0.375f, 0.875f, 0.125f, 0.625f};
  for (uint32_t i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(s.color.f(3, 4, 0, i), 3 + sx[i]);
}

TEST(RasterDepth, EarlyFragmentTestsWriteDepthEvenWhenDiscarded) {
  for (bool early : {false, true}) {
    Harness h(8, 8);
    Image depth(8, 8, 4);
    h.target.depthStencil.depthFormat = DepthFormat::D32SFloat;
    h.target.depthStencil.depth = depth.surface();
    h.target.depthStencil.depthTexelBytes = 4;
    depth.fillF({1, 1, 1, 1});
    h.state.depthTest = h.state.depthWrite = true;
    h.fs.canDiscard = true;
    h.fs.earlyFragmentTests = early;
    h.killAll = true;
    std::atomic<uint64_t> samplesPassed{0};
    h.draw.samplesPassed = &samplesPassed;
    h.vertex(0, 0, 0.25f), h.vertex(8, 0, 0.25f), h.vertex(0, 8, 0.25f);
    h.run();
    EXPECT_EQ(depth.f(1, 1), early ? 0.25f : 1.0f);
    EXPECT_EQ(h.color.f(1, 1, 3), 0.0f);
    // Sample counting: with early tests it comes before the shader's discard ("Early Fragment Test Mode"), so it
    // counts every sample whose depth the early test wrote; without, the discard leaves nothing to count.
    uint64_t written = 0;
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t x = 0; x < 8; ++x) written += depth.f(x, y) == 0.25f;
    EXPECT_EQ(samplesPassed.load(), early ? written : 0u) << "early " << early;
    if (early) {
      EXPECT_GT(written, 20u);
    }
  }
}

}  // namespace
}  // namespace vkrt::raster::test
