// The geometry side: clipping (near plane, vertices behind the eye, clip and cull distances), culling and winding,
// interpolation (perspective, linear, flat), primitive restart and IDs, points, lines, multiview.
#include <gtest/gtest.h>

#include <cmath>

#include "raster_harness.hpp"

namespace vkrt::raster::test {
namespace {

TEST(RasterInterpolation, PerspectiveLinearAndFlat) {
  const double X[3] = {4, 60, 10}, Y[3] = {6, 20, 58}, W[3] = {1, 4, 2};
  const Vec4 a[3] = {{1, 0, 0, 1}, {0, 10, 0, 1}, {0, 0, 100, 1}};
  for (int mode = 0; mode < 3; ++mode) {
    for (bool last : {false, true}) {
      Harness h;
      h.mode = FragMode::Input0;
      h.state.lastVertexProvoking = last;
      for (int i = 0; i < 3; ++i) h.vertex(float(X[i]), float(Y[i]), 0.5f, float(W[i]));
      const Interpolation kinds[3] = {Interpolation::Smooth, Interpolation::NoPerspective, Interpolation::Flat};
      h.addInput(kinds[mode], {a[0], a[1], a[2]});
      h.run();
      int checked = 0;
      for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
          double b[3];
          bary(X, Y, x + 0.5, y + 0.5, b);
          if (b[0] < 0.01 || b[1] < 0.01 || b[2] < 0.01) continue;  // well inside only
          for (int c = 0; c < 3; ++c) {
            double expected;
            if (mode == 0) {
              const double den = b[0] / W[0] + b[1] / W[1] + b[2] / W[2];
              expected = (b[0] * a[0][c] / W[0] + b[1] * a[1][c] / W[1] + b[2] * a[2][c] / W[2]) / den;
            } else if (mode == 1) {
              expected = b[0] * a[0][c] + b[1] * a[1][c] + b[2] * a[2][c];
            } else {
              expected = a[last ? 2 : 0][c];
            }
            ASSERT_NEAR(h.color.f(x, y, c), expected, 1e-3 * (1 + std::fabs(expected))) << x << "," << y;
          }
          ++checked;
        }
      EXPECT_GT(checked, 300);
    }
  }
}

// Single-sampled quads interpolate their four lanes at once (tile.cpp interpolateQuad, float perspective weights);
// 4-sample quads lane by lane (interpolateLane, double). At a pixel all 4 samples cover, both interpolate at the
// centre: the same values within float rounding, for every interpolation kind.
TEST(RasterInterpolation, QuadAtOnceMatchesLaneByLane) {
  const float X[3] = {3, 61, 9}, Y[3] = {5, 21, 59}, W[3] = {1, 5, 2.5f};
  const Vec4 a[3] = {{1, -2, 0.25f, 7}, {0, 10, 3, -1}, {-4, 0, 100, 0.5f}};
  for (Interpolation kind : {Interpolation::Smooth, Interpolation::NoPerspective, Interpolation::Flat}) {
    std::vector<float> one, four;
    for (uint32_t samples : {1u, 4u}) {
      Harness h(64, 64, samples);
      h.mode = FragMode::Input0;
      for (int i = 0; i < 3; ++i) h.vertex(X[i], Y[i], 0.5f, W[i]);
      h.addInput(kind, {a[0], a[1], a[2]});
      h.run();
      std::vector<float>& out = samples == 1 ? one : four;
      for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 64; ++x)
          for (uint32_t c = 0; c < 4; ++c) {
            bool all = true;  // every sample written (the clear value is 0 in every component)
            for (uint32_t s = 0; s < samples; ++s) all = all && h.color.f(x, y, 3, s) != 0;
            out.push_back(all ? h.color.f(x, y, c) : NAN);
          }
    }
    int compared = 0;
    for (size_t i = 0; i < one.size(); ++i) {
      if (std::isnan(one[i]) || std::isnan(four[i])) continue;
      ASSERT_NEAR(one[i], four[i], 2e-5 * (1 + std::fabs(four[i]))) << "kind " << int(kind) << " at " << i / 4;
      ++compared;
    }
    EXPECT_GT(compared, 4 * 800);
  }
}

// The quad path writes the components equal at a triangle's three vertices once per triangle and interpolates only
// the others (tile.cpp setupQuadInterp): two triangles of one tile with different constants each show their own,
// exactly, and a mix of varying, constant and undeclared components in Smooth and NoPerspective slots gives what
// the 4-sample path, which interpolates every lane and component, gives at fully covered pixels.
TEST(RasterInterpolation, ConstantComponentsAreEachTrianglesOwn) {
  // Two triangles splitting the square, with perspective; slot 0: x varies, y constant per triangle, z a negative
  // zero everywhere (kept on the varying path), w undeclared; slot 1 (NoPerspective): x constant, y varies; slot 2
  // (Smooth): all four constant, the same for both triangles.
  const float X[6] = {0, 64, 0, 64, 64, 0}, Y[6] = {0, 0, 64, 0, 64, 64}, W[6] = {1, 3, 2, 3, 1.5f, 2};
  const float kConst[2] = {0.375f, 0.625f};
  // The one-sample draws first: a worker's quad keeps what the draw before wrote, so a component the quad path
  // failed to write would otherwise still hold a 4-sample draw's value of the same geometry.
  std::vector<float> out[2][3];  // [4 samples][slot]
  for (uint32_t samples : {1u, 4u}) {
    for (uint32_t slot = 0; slot < 3; ++slot) {
      Harness h(64, 64, samples);
      h.mode = FragMode::Input0;
      h.inputSlot = slot;
      std::vector<Vec4> s0, s1, s2;
      for (int i = 0; i < 6; ++i) {
        h.vertex(X[i], Y[i], 0.5f, W[i]);
        s0.push_back(Vec4{float(i) * 3 - 1, kConst[i / 3], -0.0f, float(i)});
        s1.push_back(Vec4{-2.5f, float(i) * 0.5f, 0, 0});
        s2.push_back(Vec4{1, 2, 3, 4});
      }
      h.addInput(Interpolation::Smooth, s0);
      h.fs.inputs[0].componentMask = 0x7;
      h.addInput(Interpolation::NoPerspective, s1);
      h.fs.inputs[1].componentMask = 0x3;
      h.addInput(Interpolation::Smooth, s2);
      h.run();
      for (uint32_t y = 0; y < 64; ++y)
        for (uint32_t x = 0; x < 64; ++x) {
          const uint32_t prim = h.primIds[y * 64 + x];
          if (prim == ~0u) continue;
          if (samples == 1 && slot == 0) {
            ASSERT_EQ(h.color.f(x, y, 1), kConst[prim]) << x << "," << y;
            ASSERT_EQ(h.color.f(x, y, 2), 0.0f) << x << "," << y;
          }
          if (samples == 1 && slot == 1) {
            ASSERT_EQ(h.color.f(x, y, 0), -2.5f) << x << "," << y;
          }
          if (samples == 1 && slot == 2) {
            for (uint32_t c = 0; c < 4; ++c) ASSERT_EQ(h.color.f(x, y, c), float(c + 1)) << x << "," << y;
          }
          // Away from the diagonal every sample of the pixel is one triangle's.
          const bool whole = std::fabs(float(x + y + 1) - 64) > 1.5f;
          const uint32_t declared = slot == 0 ? 3 : slot == 1 ? 2 : 4;
          for (uint32_t c = 0; c < declared; ++c) out[samples == 4][slot].push_back(whole ? h.color.f(x, y, c) : NAN);
        }
    }
  }
  int compared = 0;
  for (uint32_t slot = 0; slot < 3; ++slot) {
    const std::vector<float>&one = out[0][slot], &four = out[1][slot];
    ASSERT_EQ(one.size(), four.size());
    for (size_t i = 0; i < one.size(); ++i) {
      if (std::isnan(one[i]) || std::isnan(four[i])) continue;
      ASSERT_NEAR(one[i], four[i], 2e-5 * (1 + std::fabs(four[i]))) << "slot " << slot << " at " << i;
      ++compared;
    }
  }
  EXPECT_GT(compared, 3 * 3000);
}

TEST(RasterClip, NearPlaneCutsTheTriangle) {
  // Orthographic (w = 1): z from -0.5 to 1 across the triangle; z_c < 0 is clipped, so a pixel is drawn when its
  // interpolated z is >= 0.
  Harness h;
  countWrites(h);
  const double X[3] = {4, 60, 4}, Y[3] = {4, 4, 60}, Z[3] = {-0.5, 1, 1};
  for (int i = 0; i < 3; ++i) h.vertex(float(X[i]), float(Y[i]), float(Z[i]));
  h.run();
  int drawn = 0;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      double b[3];
      bary(X, Y, x + 0.5, y + 0.5, b);
      const double z = b[0] * Z[0] + b[1] * Z[1] + b[2] * Z[2];
      const double edge = std::min({b[0], b[1], b[2]});
      if (std::fabs(edge) < 0.02 || std::fabs(z) < 0.02) continue;
      const float expected = edge > 0 && z > 0 ? 1.0f : 0.0f;
      ASSERT_EQ(h.color.f(x, y), expected) << x << "," << y;
      drawn += expected > 0;
    }
  EXPECT_GT(drawn, 500);
}

TEST(RasterClip, VertexBehindTheEye) {
  // A floor triangle in view space (y = -1) with one vertex behind the eye (w < 0). Projection: x_c = x, y_c = y,
  // w_c = -z, z_c = w_c - 0.1. Expected: the pixel's ray hits the floor inside the triangle, in front of the near
  // plane; and the perspective-correct input (the view-space x and z) is the hit point.
  Harness h;
  h.mode = FragMode::Input0;
  const double V[3][3] = {{0, -1, 2}, {-3, -1, -4}, {3, -1, -4}};
  std::vector<Vec4> values;
  for (const auto& v : V) {
    const float w = float(-v[2]);
    h.pos.push_back(Vec4{float(v[0]), float(v[1]), w - 0.1f, w});
    values.push_back(Vec4{float(v[0]), float(v[2]), 0, 1});
  }
  h.addInput(Interpolation::Smooth, values);
  h.color.fillF({0, 0, 0, 0});
  h.run();
  int hits = 0;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) {
      const double nx = (x + 0.5) / 32 - 1, ny = (y + 0.5) / 32 - 1;  // NDC; the ray is (nx, ny, -1) * t
      bool inside = false, clear = true;
      double hx = 0, hz = 0;
      if (ny < 0) {
        const double t = -1 / ny;
        hx = nx * t, hz = -t;
        // Inside the triangle in the xz plane, with a margin.
        double minD = 1e9;
        bool in = true;
        for (int i = 0; i < 3; ++i) {
          const int j = (i + 1) % 3;
          const double ex = V[j][0] - V[i][0], ez = V[j][2] - V[i][2];
          const double d = (ex * (hz - V[i][2]) - ez * (hx - V[i][0])) / std::sqrt(ex * ex + ez * ez);
          minD = std::min(minD, std::fabs(d));
          in = in && d > 0;
        }
        inside = in && t > 0.1;
        clear = minD > 0.1 && std::fabs(t - 0.1) > 0.01;
      }
      if (!clear) continue;
      const bool drawn = h.color.f(x, y, 3) == 1.0f;
      ASSERT_EQ(drawn, inside) << x << "," << y;
      if (inside) {
        ++hits;
        EXPECT_NEAR(h.color.f(x, y, 0), hx, 2e-3 * (1 + std::fabs(hx)));
        EXPECT_NEAR(h.color.f(x, y, 1), hz, 2e-3 * (1 + std::fabs(hz)));
      }
    }
  EXPECT_GT(hits, 200);
}

TEST(RasterClip, ClipAndCullDistances) {
  // Clip distance = x_f - 20: the left part is cut at x = 20.
  Harness h;
  countWrites(h);
  h.vs.clipDistanceCount = 1;
  h.vertex(4, 4), h.vertex(60, 4), h.vertex(4, 60);
  h.clipDist = {{4 - 20.0f, 60 - 20.0f, 4 - 20.0f}};
  h.run();
  EXPECT_EQ(h.color.f(19, 10), 0.0f);
  EXPECT_EQ(h.color.f(20, 10), 1.0f);
  // Cull distance negative at every vertex: dropped; negative at two only: kept whole.
  Harness c;
  countWrites(c);
  c.vs.cullDistanceCount = 1;
  c.vertex(4, 4), c.vertex(60, 4), c.vertex(4, 60);
  c.clipDist = {{-1, -1, -1}};
  c.run();
  EXPECT_EQ(c.color.f(10, 10), 0.0f);
  c.clipDist = {{-1, 1, -1}};
  c.run();
  EXPECT_EQ(c.color.f(5, 5), 1.0f);
}

TEST(RasterCull, WindingFrontFaceAndStrips) {
  // (10,10) (10,50) (50,10): positive area by the spec's formula, counter-clockwise.
  struct Case {
    FrontFace face;
    uint8_t cull;
    float expected;  // 0: culled; 1: drawn front; 2: drawn back
  } cases[] = {{FrontFace::CounterClockwise, 0, 1},
               {FrontFace::CounterClockwise, CullBack, 1},
               {FrontFace::CounterClockwise, CullFront, 0},
               {FrontFace::Clockwise, 0, 2},
               {FrontFace::Clockwise, CullBack, 0},
               {FrontFace::Clockwise, CullFront, 2},
               {FrontFace::CounterClockwise, CullFront | CullBack, 0}};
  for (const Case& k : cases) {
    for (Topology topo : {Topology::TriangleList, Topology::TriangleStrip, Topology::TriangleFan}) {
      Harness h;
      h.mode = FragMode::Facing;
      h.state.frontFace = k.face;
      h.state.cullMode = k.cull;
      h.state.topology = topo;
      // Strip: (10,10) (10,50) (50,10) (50,50): the second triangle (odd) keeps the first's winding.
      // Fan: centre (10,10) then (10,50) (50,10)... as (v1, v2, v0); then (50,10) (40,0)...
      h.vertex(10, 10), h.vertex(10, 50), h.vertex(50, 10);
      if (topo == Topology::TriangleStrip) h.vertex(50, 50);
      if (topo == Topology::TriangleFan) h.vertex(30, 2);
      h.run();
      EXPECT_EQ(h.color.f(15, 15), k.expected) << int(k.face) << " " << int(k.cull) << " " << int(topo);
      if (topo == Topology::TriangleStrip) {
        EXPECT_EQ(h.color.f(45, 45), k.expected);
      }
      if (topo == Topology::TriangleFan) {
        EXPECT_EQ(h.color.f(30, 6), k.expected);
      }
    }
  }
}

TEST(RasterAssembly, PrimitiveRestartAndIds) {
  Harness h;
  h.state.topology = Topology::TriangleStrip;
  h.state.primitiveRestart = true;
  // Strip A: 0 1 2 3 (two triangles); restart; strip B: 4 5 6.
  h.vertex(2, 2), h.vertex(2, 20), h.vertex(20, 2), h.vertex(20, 20);
  h.vertex(40, 40), h.vertex(40, 60), h.vertex(60, 40);
  const uint16_t idx[] = {0, 1, 2, 3, 0xFFFF, 4, 5, 6};
  h.draw.indexType = IndexType::UInt16;
  h.draw.indices = idx;
  h.draw.indexBytes = sizeof(idx);
  h.run(8);
  EXPECT_EQ(h.primIds[5 * 64 + 5], 0u);
  EXPECT_EQ(h.primIds[18 * 64 + 18], 1u);
  EXPECT_EQ(h.primIds[42 * 64 + 42], 2u);   // restart does not count
  EXPECT_EQ(h.primIds[30 * 64 + 30], ~0u);  // no triangle bridges the restart
  // Without restart, 0xFFFF is an index (reads vertex 0 in this shader) and bridges.
  Harness n;
  n.state.topology = Topology::TriangleStrip;
  n.pos = h.pos;
  n.draw.indexType = IndexType::UInt16;
  n.draw.indices = idx;
  n.draw.indexBytes = sizeof(idx);
  n.run(8);
  EXPECT_NE(n.primIds[42 * 64 + 42], ~0u);
  // Indices past indexBytes read 0.
  Harness r;
  r.pos = h.pos;
  const uint32_t idx32[] = {4, 5, 6, 1};
  r.draw.indexType = IndexType::UInt32;
  r.draw.indices = idx32;
  r.draw.indexBytes = 12;  // the 4th index and beyond read as 0
  r.draw.count = 6;        // triangles (4,5,6) and (0,0,0)
  r.draw.varyingCount = 0;
  raster::draw(r.target, r.state, r.draw, r.vs, r.fs);
  EXPECT_EQ(r.primIds[42 * 64 + 42], 0u);
}

TEST(RasterPoint, SizeAndPointCoord) {
  Harness h;
  h.mode = FragMode::PointCoord;
  h.state.topology = Topology::PointList;
  h.vertex(20, 20);
  h.vertex(40.5f, 40.5f);
  h.pointSize = {4, 100};
  h.run(1);  // the first point only
  for (uint32_t y = 16; y < 24; ++y)
    for (uint32_t x = 16; x < 24; ++x) {
      const bool in = x >= 18 && x < 22 && y >= 18 && y < 22;
      ASSERT_EQ(h.color.f(x, y, 3), in ? 1.0f : 0.0f) << x << "," << y;
      if (in) {
        EXPECT_FLOAT_EQ(h.color.f(x, y, 0), 0.5f + (x + 0.5f - 20) / 4);
        EXPECT_FLOAT_EQ(h.color.f(x, y, 1), 0.5f + (y + 0.5f - 20) / 4);
      }
    }
  // Size 1 on a pixel centre: exactly that pixel.
  Harness one;
  countWrites(one);
  one.state.topology = Topology::PointList;
  one.vertex(7.5f, 9.5f);
  one.run();
  float sum = 0;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 64; ++x) sum += one.color.f(x, y);
  EXPECT_EQ(sum, 1.0f);
  EXPECT_EQ(one.color.f(7, 9), 1.0f);
}

TEST(RasterLine, WidthOneCoverage) {
  // Horizontal: (5.5, 10.5) -> (20.5, 10.5) covers pixels 5..19 of row 10.
  Harness h;
  countWrites(h);
  h.state.topology = Topology::LineList;
  h.vertex(5.5f, 10.5f), h.vertex(20.5f, 10.5f);
  // x-major diagonal: one pixel per column.
  h.vertex(2, 30.3f), h.vertex(40, 50.1f);
  h.run();
  for (uint32_t x = 0; x < 30; ++x) {
    EXPECT_EQ(h.color.f(x, 10), x >= 5 && x < 20 ? 1.0f : 0.0f) << x;
    EXPECT_EQ(h.color.f(x, 9), 0.0f);
    EXPECT_EQ(h.color.f(x, 11), 0.0f);
  }
  for (uint32_t x = 2; x < 40; ++x) {
    float column = 0;
    for (uint32_t y = 25; y < 56; ++y) column += h.color.f(x, y);
    EXPECT_EQ(column, 1.0f) << x;
  }
}

TEST(RasterMultiview, EachViewRendersItsLayer) {
  Harness h;
  h.color = Image(64, 64, 16, 1, 3);
  h.mode = FragMode::Facing;
  h.target.viewMask = 0b101;
  h.vertex(0, 0), h.vertex(64, 0), h.vertex(0, 64);
  h.run();
  EXPECT_EQ(h.color.f(5, 5, 1, 0, 0), 0.0f);  // view 0: viewIndex 0
  EXPECT_EQ(h.color.f(5, 5, 3, 0, 0), 1.0f);
  EXPECT_EQ(h.color.f(5, 5, 3, 0, 1), 0.0f);  // layer 1 untouched
  EXPECT_EQ(h.color.f(5, 5, 1, 0, 2), 2.0f);  // view 2
  EXPECT_EQ(h.color.f(5, 5, 2, 0, 2), 2.0f);
}

TEST(RasterAssembly, InstancesKeepOrder) {
  // Two instances; the vertex shader ignores the instance so instance 1 draws over instance 0 with the same
  // primitive IDs; the draw must still write each pixel (count 2 with additive blending).
  Harness h;
  countWrites(h);
  h.draw.instanceCount = 2;
  h.vertex(0, 0), h.vertex(64, 0), h.vertex(0, 64);
  h.run();
  EXPECT_EQ(h.color.f(3, 3), 2.0f);
}

}  // namespace
}  // namespace vkrt::raster::test

namespace vkrt::raster::test {
namespace {

TEST(RasterAssembly, ProvokingVertexPerTopology) {
  // Flat input = the vertex's index; each primitive's pixels show its provoking vertex.
  struct Case {
    Topology topo;
    std::vector<std::array<float, 2>> verts;
    std::array<float, 2> probe[2];  // a pixel inside primitive 0 and 1
    float first[2], last[2];
  };
  const Case cases[] = {
      // Strip (0,1,2) then odd (1,3,2): provoking v0 / v2, then v1 / v3.
      {Topology::TriangleStrip, {{4, 4}, {4, 40}, {40, 4}, {40, 40}}, {{8, 8}, {36, 36}}, {0, 1}, {2, 3}},
      // Fan (v1, v2, v0), (v2, v3, v0): provoking v1 / v2, then v2 / v3.
      {Topology::TriangleFan, {{4, 4}, {4, 40}, {40, 40}, {40, 4}}, {{8, 30}, {30, 8}}, {1, 2}, {2, 3}},
      // Line strip: segment i provoked by v_i / v_i+1.
      {Topology::LineStrip, {{2, 10.5f}, {30, 10.5f}, {30, 40.5f}}, {{10, 10}, {29, 20}}, {0, 1}, {1, 2}},
  };
  for (const Case& c : cases) {
    for (bool last : {false, true}) {
      Harness h;
      h.mode = FragMode::Input0;
      h.state.topology = c.topo;
      h.state.lastVertexProvoking = last;
      std::vector<Vec4> values;
      for (size_t i = 0; i < c.verts.size(); ++i) {
        h.vertex(c.verts[i][0], c.verts[i][1]);
        values.push_back(Vec4{float(i), 0, 0, 1});
      }
      h.addInput(Interpolation::Flat, values);
      h.color.fillF({-1, 0, 0, 0});
      h.run();
      for (int p = 0; p < 2; ++p) {
        const uint32_t x = uint32_t(c.probe[p][0]), y = uint32_t(c.probe[p][1]);
        EXPECT_EQ(h.color.f(x, y), last ? c.last[p] : c.first[p]) << int(c.topo) << " last " << last << " prim " << p;
      }
    }
  }
}

}  // namespace
}  // namespace vkrt::raster::test

namespace vkrt::raster::test {
namespace {

TEST(RasterClip, DegenerateAndNonFiniteVerticesAreSafe) {
  // A NaN vertex, an infinite one, w = 0 and huge coordinates: nothing crashes or overflows (ASan/UBSan), and a
  // sane triangle in the same draw still renders.
  Harness h;
  countWrites(h);
  const float nan = std::nanf(""), inf = INFINITY;
  h.pos = {{nan, 0, 0.5f, 1},
           {0.5f, 0.5f, 0.5f, 1},
           {0, 0.9f, 0.5f, 1},
           {inf, 0, 0.5f, 1},
           {0.5f, 0.5f, 0.5f, 1},
           {0, 0.9f, 0.5f, 1},
           {0, 0, 0, 0},
           {0.5f, 0.5f, 0.5f, 1},
           {0, 0.9f, 0.5f, 1},
           {1e30f, -1e30f, 0.5f, 1},
           {-1e30f, 1e30f, 0.5f, 1},
           {1e30f, 1e30f, 0.5f, 1}};
  h.vertex(1, 1), h.vertex(1, 6), h.vertex(6, 1);
  h.run();
  EXPECT_GE(h.color.f(2, 2), 1.0f);
}

}  // namespace
}  // namespace vkrt::raster::test

namespace vkrt::raster::test {
namespace {

TEST(RasterPolygonMode, LineModeDrawsEdgesWithDepthBias) {
  Harness h;
  Image depth(64, 64, 4);
  depth.fillF({1, 1, 1, 1});
  h.target.depthStencil.depthFormat = DepthFormat::D32SFloat;
  h.target.depthStencil.depth = depth.surface();
  h.target.depthStencil.depthTexelBytes = 4;
  h.state.depthTest = h.state.depthWrite = true;
  h.state.depthCompare = CompareOp::Always;
  h.state.depthBiasEnable = true;
  h.state.depthBiasConstant = 1000;
  h.state.polygonMode = PolygonMode::Line;
  h.vertex(10.5f, 10.5f), h.vertex(10.5f, 40.5f), h.vertex(40.5f, 10.5f);
  h.run();
  EXPECT_EQ(h.color.f(20, 10, 3), 1.0f);  // top edge (x-major line on row 10)
  EXPECT_EQ(h.color.f(10, 20, 3), 1.0f);  // left edge (y-major line: column 10)
  EXPECT_EQ(h.color.f(18, 18, 3), 0.0f);  // interior
  EXPECT_FLOAT_EQ(depth.f(20, 10), float(0.5 + 1000 * std::ldexp(1.0, -24)));
}

}  // namespace
}  // namespace vkrt::raster::test

namespace vkrt::raster::test {
namespace {

TEST(RasterClip, DepthClampKeepsFarGeometryAndDiscardDrawsNothing) {
  // z_c = 1.5 w_c is past the far plane: clipped normally; with depth clamp (no depth clip) drawn at the
  // viewport's maxDepth.
  for (bool clamp : {false, true}) {
    Harness h;
    Image depth(64, 64, 4);
    depth.fillF({1, 1, 1, 1});
    h.target.depthStencil.depthFormat = DepthFormat::D32SFloat;
    h.target.depthStencil.depth = depth.surface();
    h.target.depthStencil.depthTexelBytes = 4;
    h.state.viewports[0].minDepth = 0.2f;
    h.state.viewports[0].maxDepth = 0.8f;
    h.state.depthTest = h.state.depthWrite = true;
    h.state.depthCompare = CompareOp::Always;
    h.state.depthClamp = clamp;
    h.state.depthClipEnable = !clamp;
    h.vertex(0, 0, 1.5f), h.vertex(64, 0, 1.5f), h.vertex(0, 64, 1.5f);
    h.run();
    EXPECT_EQ(h.color.f(5, 5, 3), clamp ? 1.0f : 0.0f);
    EXPECT_EQ(depth.f(5, 5), clamp ? 0.8f : 1.0f);
  }
  // Rasterizer discard: the vertex stage runs, nothing is rasterized.
  Harness d;
  countWrites(d);
  d.state.rasterizerDiscard = true;
  static int calls;
  calls = 0;
  d.vs.shade = [](void* user, uint32_t inst, uint32_t view, const uint32_t* idx, uint32_t n, ShadedVertex* out,
                  unsigned w) {
    ++calls;  // one chunk: the draw has 3 vertices
    Harness::vertexShader(user, inst, view, idx, n, out, w);
  };
  d.vertex(0, 0), d.vertex(64, 0), d.vertex(0, 64);
  d.run();
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(d.color.f(5, 5), 0.0f);
}

}  // namespace
}  // namespace vkrt::raster::test
