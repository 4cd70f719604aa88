// One tile: the coverage of each triangle in 8x8 blocks and 2x2 quads (edge functions stepped incrementally in
// 64-bit integers), the interpolation of the fragment shader's inputs, the shader call and the hand-off to the
// per-fragment operations ("Rasterization": Polygon Rasterization, Multisampling, Interpolation; "Fragment
// Operations").
#include <algorithm>
#include <bit>
#include <cmath>

#include "raster/internal.hpp"

namespace vkrt::raster::detail {
namespace {

constexpr int32_t kBlock = 8;  // pixels per side of the blocks tested whole before their quads

// The sample position (in fixed point, within the pixel) of sample s.
inline int32_t sampleX(const DrawContext& ctx, uint32_t s) { return ctx.samples == 1 ? kCentre : kSampleX4[s]; }
inline int32_t sampleY(const DrawContext& ctx, uint32_t s) { return ctx.samples == 1 ? kCentre : kSampleY4[s]; }

inline float depthAt(const DrawContext& ctx, const SetupTri& t, int64_t px, int64_t py) {
  const double z = t.zA * (double(px) / kSubPixel) + t.zB * (double(py) / kSubPixel) + t.zC;
  return std::clamp(float(z), ctx.depthMin, ctx.depthMax);
}

using Float4 = float __attribute__((vector_size(16)));
using Float2 = float __attribute__((vector_size(8)));
using Double2 = double __attribute__((vector_size(16)));
// depthAt at the four pixel centres of a one-sample quad, into z[l][0]: the same double operations per lane, two
// lanes per vector.
inline void depthQuad(const DrawContext& ctx, const SetupTri& t, int32_t qx, int32_t qy, float z[4][4]) {
  const int64_t px = int64_t(qx) * kSubPixel + kCentre, py = int64_t(qy) * kSubPixel + kCentre;
  const Double2 x = {double(px) / kSubPixel, double(px + kSubPixel) / kSubPixel};
  for (int r = 0; r < 2; ++r) {
    const Double2 v = t.zA * x + t.zB * (double(py + r * kSubPixel) / kSubPixel) + t.zC;
    Float2 f = __builtin_convertvector(v, Float2);
    f = f < ctx.depthMin ? Float2{ctx.depthMin, ctx.depthMin} : f;  // std::clamp (NaN stays NaN)
    f = ctx.depthMax < f ? Float2{ctx.depthMax, ctx.depthMax} : f;
    z[2 * r][0] = f[0], z[2 * r + 1][0] = f[1];
  }
}

inline Float4 load4(const uint32_t* p) {
  Float4 v;
  std::memcpy(&v, p, 16);
  return v;
}

// Screen-space barycentrics at a fixed-point position (exact edge values, one division).
inline void barycentrics(const SetupTri& t, int64_t px, int64_t py, double b[3]) {
  for (int i = 0; i < 3; ++i) b[i] = double(t.a[i] * px + t.b[i] * py + t.c[i]) * t.invArea2;
}

// Fills lane `lane`'s inputs, FragCoord and PointCoord for the interpolation position (px, py), and `centroid`
// (used by centroid inputs) when it differs.
void interpolateLane(const DrawContext& ctx, const SetupTri& t, FragmentQuad& q, uint32_t lane, int64_t px, int64_t py,
                     const int64_t* centroid) {
  double b[3], bc[3];
  barycentrics(t, px, py, b);
  const double invW = b[0] * t.invW[0] + b[1] * t.invW[1] + b[2] * t.invW[2];
  q.fragCoord[lane][0] = float(px) / kSubPixel;
  q.fragCoord[lane][1] = float(py) / kSubPixel;
  q.fragCoord[lane][2] = depthAt(ctx, t, px, py);
  q.fragCoord[lane][3] = float(invW);
  if (t.isPoint) {
    // PointCoord ("Basic Point Rasterization"): s to the right, t downwards, 0.5 at the centre.
    q.pointCoord[lane][0] = 0.5f + (q.fragCoord[lane][0] - t.pointX) / t.pointSize;
    q.pointCoord[lane][1] = 0.5f + (q.fragCoord[lane][1] - t.pointY) / t.pointSize;
  } else {
    q.pointCoord[lane][0] = q.pointCoord[lane][1] = 0;
  }
  const FragmentStage& fs = *ctx.fragment;
  if (!fs.inputCount) return;
  if (centroid) barycentrics(t, centroid[0], centroid[1], bc);
  // Perspective-correct weights: b_i / w_i normalized ("Polygon Interpolation"); the sums in float.
  float p[3], pc[3], l[3], lc[3];
  auto perspective = [&](const double* in, float* out) {
    const double w0 = in[0] * t.invW[0], w1 = in[1] * t.invW[1], w2 = in[2] * t.invW[2];
    const double sum = w0 + w1 + w2;
    const double r = sum != 0 ? 1.0 / sum : 0;
    if (sum != 0) {
      out[0] = float(w0 * r), out[1] = float(w1 * r), out[2] = float(w2 * r);
    } else {
      out[0] = float(in[0]), out[1] = float(in[1]), out[2] = float(in[2]);
    }
  };
  for (int i = 0; i < 3; ++i) l[i] = float(b[i]);
  if (centroid)
    for (int i = 0; i < 3; ++i) lc[i] = float(bc[i]);
  if (ctx.hasSmooth) {
    perspective(b, p);
    if (centroid) perspective(bc, pc);
  }
  uint32_t* dst = q.inputs[lane];
  for (uint32_t slot = 0; slot < fs.inputCount; ++slot) {
    const FragmentInput& in = fs.inputs[slot];
    const uint32_t k = slot * 4;
    if (in.interpolation == Interpolation::Flat) {
      std::memcpy(dst + k, t.flat + k, 16);
      continue;
    }
    const bool useCentroid = centroid && in.centroid;
    const float* w = in.interpolation == Interpolation::Smooth ? (useCentroid ? pc : p) : (useCentroid ? lc : l);
    // f0 + w1 (f1 - f0) + w2 (f2 - f0): a value equal at the three vertices interpolates to exactly itself. The
    // four components at once (the same operations, in the same order, per component).
    const Float4 f0 = load4(t.var[0] + k);
    const Float4 v = f0 + w[1] * (load4(t.var[1] + k) - f0) + w[2] * (load4(t.var[2] + k) - f0);
    std::memcpy(dst + k, &v, 16);
  }
}

// interpolateLane for the four lanes of a single-sampled quad at once (pixel centres; with one sample a pixel is
// covered whole, so centroid inputs interpolate at the centre too): the barycentrics from the exact edge values as
// there, the perspective weights in float across the lanes (one division for four lanes instead of four in double;
// a few ulp apart), and each input's vertex differences once per quad.
void interpolateQuad(const DrawContext& ctx, const SetupTri& t, FragmentQuad& q, uint32_t lanes, int32_t qx, int32_t qy,
                     const float z[4][4]) {
  const int64_t px0 = int64_t(qx) * kSubPixel + kCentre, py0 = int64_t(qy) * kSubPixel + kCentre;
  Float4 b[3];  // per vertex, per lane
  for (int i = 0; i < 3; ++i) {
    // The edge's integer values at the four centres, converted once: every value here is below 2^53 in magnitude
    // (coordinates within 2^24 fixed-point units), so the conversions and the sums in double are exact and equal
    // the conversions of the integer sums.
    const double e = double(t.a[i] * px0 + t.b[i] * py0 + t.c[i]);
    const double dx = double(t.a[i] * kSubPixel), dy = double(t.b[i] * kSubPixel);
    const Double2 top = Double2{e, e + dx} * t.invArea2, bottom = Double2{e + dy, (e + dx) + dy} * t.invArea2;
    b[i] = __builtin_shufflevector(__builtin_convertvector(top, Float2), __builtin_convertvector(bottom, Float2), 0, 1,
                                   2, 3);
  }
  const Float4 w0 = b[0] * t.invW[0], w1 = b[1] * t.invW[1], w2 = b[2] * t.invW[2];
  const Float4 invW = w0 + w1 + w2;
  // Perspective-correct weights b_i / w_i normalized ("Polygon Interpolation"); the screen-space ones where the sum
  // is 0 (as interpolateLane).
  const Float4 r = 1.0f / invW;
  const auto zero = invW == 0.0f;
  const Float4 p1 = zero ? b[1] : w1 * r, p2 = zero ? b[2] : w2 * r;
  const FragmentStage& fs = *ctx.fragment;
  for (uint32_t l = 0; l < 4; ++l) {
    if (!(lanes >> l & 1)) continue;
    const int64_t px = px0 + int64_t(l & 1) * kSubPixel, py = py0 + int64_t(l >> 1) * kSubPixel;
    q.fragCoord[l][0] = float(px) / kSubPixel;
    q.fragCoord[l][1] = float(py) / kSubPixel;
    // The tests' depth (depthQuad: depthAt at the pixel centre, the one sample's position).
    q.fragCoord[l][2] = z[l][0];
    q.fragCoord[l][3] = invW[l];
    if (t.isPoint) {
      q.pointCoord[l][0] = 0.5f + (q.fragCoord[l][0] - t.pointX) / t.pointSize;
      q.pointCoord[l][1] = 0.5f + (q.fragCoord[l][1] - t.pointY) / t.pointSize;
    } else {
      q.pointCoord[l][0] = q.pointCoord[l][1] = 0;
    }
  }
  for (uint32_t slot = 0; slot < fs.inputCount; ++slot) {
    const FragmentInput& in = fs.inputs[slot];
    const uint32_t k = slot * 4;
    if (in.interpolation == Interpolation::Flat) {
      for (uint32_t l = 0; l < 4; ++l)
        if (lanes >> l & 1) std::memcpy(q.inputs[l] + k, t.flat + k, 16);
      continue;
    }
    const bool smooth = in.interpolation == Interpolation::Smooth;
    const Float4 f0 = load4(t.var[0] + k), d1 = load4(t.var[1] + k) - f0, d2 = load4(t.var[2] + k) - f0;
    for (uint32_t l = 0; l < 4; ++l) {
      if (!(lanes >> l & 1)) continue;
      const float u1 = smooth ? p1[l] : b[1][l], u2 = smooth ? p2[l] : b[2][l];
      const Float4 v = f0 + u1 * d1 + u2 * d2;
      std::memcpy(q.inputs[l] + k, &v, 16);
    }
  }
}

// After the shader: discard, the shader's sample mask, alpha to coverage, the late tests, the color writes.
void finishQuad(const DrawContext& ctx, const SetupTri& t, FragmentQuad& q, float z[4][4], WorkerScratch& scratch) {
  const State& st = *ctx.state;
  const FragmentStage& fs = *ctx.fragment;
  uint32_t passed[4] = {0, 0, 0, 0};  // the samples each lane writes (lanes are distinct pixels: tests first)
  if (ctx.plainFinish) {
    // Nothing between the shader and the colour writes but discard (the tests ran before the shader).
    for (uint32_t l = 0; l < 4; ++l) passed[l] = (q.killed >> l & 1) ? 0 : q.coverage[l];
    if (passed[0] | passed[1] | passed[2] | passed[3]) writeQuadColors(ctx, q, passed);
    return;
  }
  for (uint32_t l = 0; l < 4; ++l) {
    uint32_t c = q.coverage[l];
    if (!c || (q.killed >> l & 1)) continue;
    if (fs.writesSampleMask) c &= q.sampleMaskOut[l];
    if (st.alphaToCoverage && (fs.outputMask & 1)) c &= alphaCoverage(asFloat(q.color[l][0][3]), ctx.samples);
    if (!ctx.earlyTests && c && fs.writesDepth) {
      float d = q.depth[l];
      if (st.depthClamp) d = std::clamp(d, ctx.depthMin, ctx.depthMax);
      for (uint32_t s = 0; s < ctx.samples; ++s) z[l][s] = d;
    }
    passed[l] = c;
  }
  uint32_t any = passed[0] | passed[1] | passed[2] | passed[3];
  if (!ctx.earlyTests && any) any = ctx.backEnd.depthStencil(ctx, t.front, q.x, q.y, passed, z);
  if (!any) return;
  for (uint32_t l = 0; l < 4; ++l) {
    if (!passed[l]) continue;
    if (ctx.draw->samplesPassed && !ctx.earlyTests)                 // counted before the shader with early tests
      scratch.samplesPassed += uint32_t(std::popcount(passed[l]));  // (shadeQuad); a library call without POPCNT
    if (st.alphaToOne && (fs.outputMask & 1)) q.color[l][0][3] = asWord(1.0f);
  }
  writeQuadColors(ctx, q, passed);
}

// One quad with its per-lane coverage (already limited to the clip rectangle).
void shadeQuad(const DrawContext& ctx, const SetupTri& t, int32_t qx, int32_t qy, uint32_t cov[4],
               WorkerScratch& scratch, unsigned worker) {
  const State& st = *ctx.state;
  const FragmentStage& fs = *ctx.fragment;
  uint32_t any = 0;
  for (uint32_t l = 0; l < 4; ++l) any |= cov[l] &= st.sampleMask;
  if (!any) return;
  float z[4][4];
  if (ctx.samples == 1 && !ctx.perSample) {
    depthQuad(ctx, t, qx, qy, z);  // all four lanes: the tests' depths and FragCoord.z (interpolateQuad)
  } else {
    for (uint32_t l = 0; l < 4 && ctx.needsDepth; ++l) {
      if (!cov[l]) continue;
      const int64_t px = int64_t(qx + int32_t(l & 1)) * kSubPixel, py = int64_t(qy + int32_t(l >> 1)) * kSubPixel;
      for (uint32_t s = 0; s < ctx.samples; ++s) z[l][s] = depthAt(ctx, t, px + sampleX(ctx, s), py + sampleY(ctx, s));
    }
  }
  if (ctx.earlyTests) {
    if (!ctx.backEnd.depthStencil(ctx, t.front, qx, qy, cov, z)) return;
    // With early tests, sample counting comes before fragment shading and the multisample coverage operations
    // (discard, the shader's sample mask, alpha to coverage): "Early Fragment Test Mode" says they should be
    // performed after it.
    if (ctx.draw->samplesPassed || !fs.shade)
      for (uint32_t l = 0; l < 4; ++l) scratch.samplesPassed += uint32_t(std::popcount(cov[l]));
    if (!fs.shade) return;  // no fragment shader: the early tests are all there is
  }
  FragmentQuad& q = scratch.quad;
  q.x = qx, q.y = qy;
  q.frontFacing = t.front;
  q.primitiveId = t.primitiveId;
  q.viewIndex = ctx.viewIndex;
  q.layer = ctx.layer;
  q.primitive = &t;  // for interpolateAt
  q.drawContext = &ctx;
  const uint32_t lanes =
      fs.needsHelpers ? 0xF : ((cov[0] ? 1 : 0) | (cov[1] ? 2 : 0) | (cov[2] ? 4 : 0) | (cov[3] ? 8 : 0));
  if (ctx.perSample) {
    // Sample shading: once per sample any lane covers, at that sample's position.
    for (uint32_t s = 0; s < ctx.samples; ++s) {
      if (!(any >> s & 1)) continue;
      uint32_t sampleLanes = 0;
      for (uint32_t l = 0; l < 4; ++l) {
        q.coverage[l] = cov[l] & (1u << s);
        if (q.coverage[l]) sampleLanes |= 1u << l;
      }
      if (!sampleLanes) continue;
      q.sampleIndex = s;
      for (uint32_t l = 0; l < 4; ++l) {
        if (!(fs.needsHelpers ? true : (sampleLanes >> l & 1))) continue;
        const int64_t px = int64_t(qx + int32_t(l & 1)) * kSubPixel + sampleX(ctx, s);
        const int64_t py = int64_t(qy + int32_t(l >> 1)) * kSubPixel + sampleY(ctx, s);
        interpolateLane(ctx, t, q, l, px, py, nullptr);
      }
      q.killed = 0;
      for (uint32_t l = 0; l < 4; ++l) q.sampleMaskOut[l] = ~0u;
      fs.shade(fs.user, q, worker);
      finishQuad(ctx, t, q, z, scratch);
    }
    return;
  }
  q.sampleIndex = 0;
  for (uint32_t l = 0; l < 4; ++l) q.coverage[l] = cov[l];
  if (ctx.samples == 1) {
    interpolateQuad(ctx, t, q, lanes, qx, qy, z);
  } else {
    for (uint32_t l = 0; l < 4; ++l) {
      if (!(lanes >> l & 1)) continue;
      const int64_t px = int64_t(qx + int32_t(l & 1)) * kSubPixel + kCentre;
      const int64_t py = int64_t(qy + int32_t(l >> 1)) * kSubPixel + kCentre;
      // Centroid: the pixel centre when every sample is covered, else the first covered sample (inside the
      // primitive and the pixel, as "Centroid Interpolation" asks).
      int64_t centroid[2];
      const bool partial = cov[l] && cov[l] != ctx.allSamples;
      if (partial) {
        const uint32_t s = uint32_t(std::countr_zero(cov[l]));
        centroid[0] = px - kCentre + sampleX(ctx, s);
        centroid[1] = py - kCentre + sampleY(ctx, s);
      }
      interpolateLane(ctx, t, q, l, px, py, partial ? centroid : nullptr);
    }
  }
  q.killed = 0;
  for (uint32_t l = 0; l < 4; ++l) q.sampleMaskOut[l] = ~0u;
  fs.shade(fs.user, q, worker);
  finishQuad(ctx, t, q, z, scratch);
}

// Largest and smallest value of edge i over the pixel rectangle [x0, x1) x [y0, y1) (pixels), bias included.
inline int64_t edgeMax(const SetupTri& t, int i, int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
  return t.a[i] * (t.a[i] > 0 ? x1 : x0) * kSubPixel + t.b[i] * (t.b[i] > 0 ? y1 : y0) * kSubPixel + t.c[i] +
         t.cBias[i];
}
inline int64_t edgeMin(const SetupTri& t, int i, int64_t x0, int64_t y0, int64_t x1, int64_t y1) {
  return t.a[i] * (t.a[i] > 0 ? x0 : x1) * kSubPixel + t.b[i] * (t.b[i] > 0 ? y0 : y1) * kSubPixel + t.c[i] +
         t.cBias[i];
}

void rasterizeTriangle(const DrawContext& ctx, const SetupTri& t, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                       WorkerScratch& scratch, unsigned worker) {
  const uint32_t S = ctx.samples;
  // Per lane and sample, the offset of each edge from the quad's origin.
  int64_t off[3][16];
  for (int i = 0; i < 3; ++i)
    for (uint32_t l = 0; l < 4; ++l)
      for (uint32_t s = 0; s < S; ++s)
        off[i][l * S + s] = t.a[i] * (int64_t(l & 1) * kSubPixel + sampleX(ctx, s)) +
                            t.b[i] * (int64_t(l >> 1) * kSubPixel + sampleY(ctx, s));
  const int64_t stepX[3] = {t.a[0] * 2 * kSubPixel, t.a[1] * 2 * kSubPixel, t.a[2] * 2 * kSubPixel};
  const int32_t bx0 = x0 & ~(kBlock - 1), by0 = y0 & ~(kBlock - 1);
  for (int32_t by = by0; by <= y1; by += kBlock) {
    for (int32_t bx = bx0; bx <= x1; bx += kBlock) {
      // The block, clipped to the triangle's rectangle: skip it when an edge excludes all of it.
      const int32_t rx0 = std::max(bx, x0), ry0 = std::max(by, y0);
      const int32_t rx1 = std::min(bx + kBlock - 1, x1), ry1 = std::min(by + kBlock - 1, y1);
      bool reject = false, full = true;
      for (int i = 0; i < 3 && !reject; ++i) {
        reject = edgeMax(t, i, rx0, ry0, rx1 + 1, ry1 + 1) < 0;
        full = full && edgeMin(t, i, rx0, ry0, rx1 + 1, ry1 + 1) >= 0;
      }
      if (reject) continue;
      for (int32_t qy = ry0 & ~1; qy <= ry1; qy += 2) {
        const int32_t qxStart = rx0 & ~1;
        int64_t e[3];  // the edges at the quad's origin, stepped along the row
        for (int i = 0; i < 3; ++i)
          e[i] = t.a[i] * int64_t(qxStart) * kSubPixel + t.b[i] * int64_t(qy) * kSubPixel + t.c[i] + t.cBias[i];
        for (int32_t qx = qxStart; qx <= rx1; qx += 2, e[0] += stepX[0], e[1] += stepX[1], e[2] += stepX[2]) {
          uint32_t cov[4] = {0, 0, 0, 0};
          uint32_t any = 0;
          if (full) {
            for (uint32_t l = 0; l < 4; ++l) cov[l] = ctx.allSamples;
          } else {
            for (uint32_t l = 0; l < 4; ++l) {
              uint32_t m = 0;
              for (uint32_t s = 0; s < S; ++s) {
                const uint32_t k = l * S + s;
                m |= uint32_t(((e[0] + off[0][k]) | (e[1] + off[1][k]) | (e[2] + off[2][k])) >= 0) << s;
              }
              cov[l] = m;
            }
          }
          // Lanes outside the triangle's rectangle (the clip rectangle included) are not covered.
          const bool edgeQuad = qx < rx0 || qx + 1 > rx1 || qy < ry0 || qy + 1 > ry1;
          for (uint32_t l = 0; l < 4; ++l) {
            const int32_t x = qx + int32_t(l & 1), y = qy + int32_t(l >> 1);
            if (edgeQuad && (x < rx0 || x > rx1 || y < ry0 || y > ry1)) cov[l] = 0;
            any |= cov[l];
          }
          if (any) shadeQuad(ctx, t, qx, qy, cov, scratch, worker);
        }
      }
    }
  }
}

}  // namespace

void rasterizeTile(const DrawContext& ctx, const SetupTri* const* tris, size_t count, int32_t tileX, int32_t tileY,
                   WorkerScratch& scratch, unsigned worker) {
  for (size_t i = 0; i < count; ++i) {
    const SetupTri& t = *tris[i];
    const int32_t x0 = std::max(t.minX, tileX), y0 = std::max(t.minY, tileY);
    const int32_t x1 = std::min(t.maxX, tileX + kTileSize - 1), y1 = std::min(t.maxY, tileY + kTileSize - 1);
    if (x0 > x1 || y0 > y1) continue;
    rasterizeTriangle(ctx, t, x0, y0, x1, y1, scratch, worker);
  }
  if (scratch.samplesPassed) {
    if (ctx.draw->samplesPassed) ctx.draw->samplesPassed->fetch_add(scratch.samplesPassed, std::memory_order_relaxed);
    scratch.samplesPassed = 0;
  }
}

}  // namespace vkrt::raster::detail
