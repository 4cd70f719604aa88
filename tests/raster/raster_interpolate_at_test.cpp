// raster::interpolateAt, what the fragment shader's InterpolateAtCentroid / Sample / Offset call: the inputs of a
// perspective triangle evaluated at an offset, a sample position and the centroid, against barycentrics computed
// here in double from the triangle's framebuffer coordinates.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_harness.hpp"

namespace vkrt::raster::test {
namespace {

// Vertices on the 1/256-pixel grid, so that the rasterizer's coverage is the exact triangle's.
const double X[3] = {3.25, 61, 9}, Y[3] = {5.125, 21, 59.75}, W[3] = {1, 4, 2};
const Vec4 A[3] = {{1, 0, 0, 1}, {0, 10, 0, 1}, {0, 0, 100, 1}};
// Slot 0 smooth at location 0, slot 1 linear at location 3, slot 2 flat at location 5.
constexpr uint32_t kLoc[3] = {0, 3, 5};

struct Query {
  InterpolateAt where;
  int32_t sample;
  float dx, dy;
};

// The shader: color 0 = slot 0 (smooth), color 1 = slot 1 (linear), color 2 = slot 2 (flat), each interpolated at
// the query's position.
struct Shader {
  Harness* h;
  Query query;
  static void shade(void* user, FragmentQuad& q, unsigned) {
    auto& s = *static_cast<Shader*>(user);
    for (uint32_t l = 0; l < 4; ++l) {
      if (!q.coverage[l]) continue;
      uint32_t out[32 * 4];
      std::memset(out, 0xFF, sizeof out);
      interpolateAt(q, l, s.query.where, s.query.sample, s.query.dx, s.query.dy, out);
      for (uint32_t k = 0; k < 3; ++k) setLaneWords(q.color[k], l, out + 4 * kLoc[k]);
    }
  }
};

struct Drawn {
  Harness h{64, 64, 4};
  Image c1{64, 64, 16, 4}, c2{64, 64, 16, 4};
  Shader shader;
  explicit Drawn(Query q) {
    for (int i = 0; i < 3; ++i) h.vertex(float(X[i]), float(Y[i]), 0.5f, float(W[i]));
    h.addInput(Interpolation::Smooth, {A[0], A[1], A[2]});
    h.addInput(Interpolation::NoPerspective, {A[0], A[1], A[2]}, /*centroid=*/true);
    h.addInput(Interpolation::Flat, {A[0], A[1], A[2]});
    for (uint32_t k = 0; k < 3; ++k) h.fs.inputs[k].location = uint8_t(kLoc[k]);
    h.target.colorCount = 3;
    for (uint32_t k = 1; k < 3; ++k) h.target.colorFormat[k] = h.target.colorFormat[0];
    h.target.color[1] = c1.surface();
    h.target.color[2] = c2.surface();
    h.fs.outputMask = 7;
    shader.h = &h;
    shader.query = q;
    h.fs.user = &shader;
    h.fs.shade = &Shader::shade;
    h.run();
  }
  // Checks every pixel whose samples are all covered (sample 0 of the pixel holds the lane's output), with the
  // position (px, py) the query names.
  int check(double dx, double dy) {
    int checked = 0;
    for (uint32_t y = 0; y < 64; ++y)
      for (uint32_t x = 0; x < 64; ++x) {
        double b[3];
        bary(X, Y, x + 0.5, y + 0.5, b);
        if (b[0] < 0.05 || b[1] < 0.05 || b[2] < 0.05) continue;  // well inside: every sample covered
        bary(X, Y, x + 0.5 + dx, y + 0.5 + dy, b);
        const double den = b[0] / W[0] + b[1] / W[1] + b[2] / W[2];
        for (int c = 0; c < 3; ++c) {
          const double smooth = (b[0] * A[0][c] / W[0] + b[1] * A[1][c] / W[1] + b[2] * A[2][c] / W[2]) / den;
          const double linear = b[0] * A[0][c] + b[1] * A[1][c] + b[2] * A[2][c];
          EXPECT_NEAR(h.color.f(x, y, c), smooth, 1e-3 * (1 + std::fabs(smooth))) << x << "," << y;
          EXPECT_NEAR(c1.f(x, y, c), linear, 1e-3 * (1 + std::fabs(linear))) << x << "," << y;
          EXPECT_EQ(c2.f(x, y, c), A[0][c]) << x << "," << y;  // flat: the provoking (first) vertex
        }
        ++checked;
      }
    return checked;
  }
};

TEST(RasterInterpolateAt, OffsetFromThePixelCentre) {
  for (auto [dx, dy] : {std::pair{-0.5f, -0.5f}, {0.4375f, 0.4375f}, {0.25f, -0.3125f}}) {
    Drawn r({InterpolateAt::Offset, 0, dx, dy});
    EXPECT_GT(r.check(dx, dy), 300);
  }
}

TEST(RasterInterpolateAt, SamplePositionsOfTheStandardPattern) {
  const double sx[4] = {0.375, 0.875, 0.125, 0.625}, sy[4] = {0.125, 0.375, 0.625, 0.875};
  for (int s = 0; s < 4; ++s) {
    Drawn r({InterpolateAt::Sample, s, 0, 0});
    EXPECT_GT(r.check(sx[s] - 0.5, sy[s] - 0.5), 300);
  }
  // A sample the pixel does not have: the centre.
  Drawn r({InterpolateAt::Sample, 7, 0, 0});
  EXPECT_GT(r.check(0, 0), 300);
}

TEST(RasterInterpolateAt, CentroidIsTheCentreOfAFullPixelAndACoveredSampleOfAPartialOne) {
  Drawn r({InterpolateAt::Centroid, 0, 0, 0});
  EXPECT_GT(r.check(0, 0), 300);
  // Partly covered pixels: the value is that of a sample position inside the triangle.
  const double sx[4] = {0.375, 0.875, 0.125, 0.625}, sy[4] = {0.125, 0.375, 0.625, 0.875};
  int partial = 0;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      int inside = 0, matched = 0;
      for (int s = 0; s < 4; ++s) {
        double b[3];
        bary(X, Y, x + sx[s], y + sy[s], b);
        if (b[0] < 1e-6 || b[1] < 1e-6 || b[2] < 1e-6) continue;
        ++inside;
        const double linear = b[0] * A[0][1] + b[1] * A[1][1] + b[2] * A[2][1];
        for (int k = 0; k < 4; ++k)
          if (std::fabs(r.c1.f(x, y, 1, uint32_t(k)) - linear) < 1e-3) ++matched;
      }
      // Samples exactly on an edge go by the top-left rule, which this count does not apply: such pixels are skipped.
      bool onEdge = false;
      for (int k = 0; k < 4; ++k) {
        double b[3];
        bary(X, Y, x + sx[k], y + sy[k], b);
        onEdge = onEdge || std::fabs(b[0]) < 1e-6 || std::fabs(b[1]) < 1e-6 || std::fabs(b[2]) < 1e-6;
      }
      if (inside == 0 || inside == 4 || onEdge) continue;
      ++partial;
      EXPECT_GT(matched, 0) << "pixel " << x << "," << y << ": no covered sample's value";
    }
  EXPECT_GT(partial, 20);
}

}  // namespace
}  // namespace vkrt::raster::test
