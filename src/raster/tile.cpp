// One tile: the coverage of each triangle in 8x8 blocks and 2x2 quads (edge functions stepped incrementally in
// 64-bit integers), the interpolation of the fragment shader's inputs, the shader call and the hand-off to the
// per-fragment operations ("Rasterization": Polygon Rasterization, Multisampling, Interpolation; "Fragment
// Operations").
#include <algorithm>
#include <bit>
#include <cmath>
#include <type_traits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
// The plane and the clamp range in vectors, once per triangle (shadeQuad's calls are opaque: read through the
// triangle and the context they would be loaded again for every quad).
struct DepthPlane {
  Double2 zA, zB, zC;
  Float4 lo, hi;
};

inline DepthPlane depthPlane(const DrawContext& ctx, const SetupTri& t) {
  return {t.zA + Double2{}, t.zB + Double2{}, t.zC + Double2{}, ctx.depthMin + Float4{}, ctx.depthMax + Float4{}};
}

// A row of quads' terms of the plane: zB times the centres' y of its two pixel rows (the same products for every
// quad of the row, so made once per row).
struct DepthRow {
  Double2 top, bottom;
};

inline DepthRow depthRow(const DepthPlane& p, int32_t qy) {
  const double y = double(qy) + 0.5;
  return {p.zB * y, p.zB * (y + 1)};
}

// depthAt at the four pixel centres of a one-sample quad of `row`, into z[0] and returned (lane l in element l): the
// same double operations per lane (the centres' coordinates in pixels are the pixel index plus 0.5, exactly), two
// lanes per vector, the clamp on all four.
inline Float4 depthQuad(const DepthPlane& p, const DepthRow& row, int32_t qx, float z[4][4]) {
  const Double2 ax = p.zA * (double(qx) + Double2{0.5, 1.5});
  const Double2 top = ax + row.top + p.zC, bottom = ax + row.bottom + p.zC;
  Float4 f = __builtin_shufflevector(__builtin_convertvector(top, Float2), __builtin_convertvector(bottom, Float2), 0,
                                     1, 2, 3);
  f = f < p.lo ? p.lo : f;  // std::clamp (NaN stays NaN)
  f = p.hi < f ? p.hi : f;
  std::memcpy(z[0], &f, 16);
  return f;
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
  q.fragCoord[0][lane] = float(px) / kSubPixel;
  q.fragCoord[1][lane] = float(py) / kSubPixel;
  q.fragCoord[2][lane] = depthAt(ctx, t, px, py);
  q.fragCoord[3][lane] = float(invW);
  if (t.isPoint) {
    // PointCoord ("Basic Point Rasterization"): s to the right, t downwards, 0.5 at the centre.
    q.pointCoord[lane][0] = 0.5f + (q.fragCoord[0][lane] - t.pointX) / t.pointSize;
    q.pointCoord[lane][1] = 0.5f + (q.fragCoord[1][lane] - t.pointY) / t.pointSize;
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
  for (uint32_t slot = 0; slot < fs.inputCount; ++slot) {
    const FragmentInput& in = fs.inputs[slot];
    const uint32_t k = slot * 4;
    if (in.interpolation == Interpolation::Flat) {
      setLaneWords(q.inputs + 4 * slot, lane, t.flat + k);
      continue;
    }
    const bool useCentroid = centroid && in.centroid;
    const float* w = in.interpolation == Interpolation::Smooth ? (useCentroid ? pc : p) : (useCentroid ? lc : l);
    // f0 + w1 (f1 - f0) + w2 (f2 - f0): a value equal at the three vertices interpolates to exactly itself. The
    // four components at once (the same operations, in the same order, per component).
    const Float4 f0 = load4(t.var[0] + k);
    const Float4 v = f0 + w[1] * (load4(t.var[1] + k) - f0) + w[2] * (load4(t.var[2] + k) - f0);
    uint32_t words[4];
    std::memcpy(words, &v, 16);
    setLaneWords(q.inputs + 4 * slot, lane, words);
  }
}

// What interpolateQuad needs of a triangle that is the same for all its quads: the edges' steps between the
// quad's pixels, and the input components that vary over the triangle, each with its vertex-0 value and differences
// in all four elements (so that a quad's interpolation broadcasts nothing), the Smooth ones first. The others are
// written into the quad once per triangle (setupQuadInterp): Flat slots, and components equal at the three vertices
// (f0 + u1 (f1 - f0) + u2 (f2 - f0) is then f0 itself for any finite weights, a negative zero aside, which stays
// varying); components the shader does not declare (FragmentInput::componentMask) are never written.
struct QuadInterp {
  double dx[3], dy[3];  // a * 256, b * 256, exact
  uint32_t smoothCount = 0, count = 0;
  bool barycentrics = true;  // some component varies or the shader reads FragCoord (whose w is their sum)
  bool pointCoord = true;    // the shader reads PointCoord
  struct Component {
    Float4 f0, d1, d2;
    uint32_t row;  // FragmentQuad::inputs row: 4 slot + component
  } component[kMaxLocations * 4];
};

void setupQuadInterp(const DrawContext& ctx, const SetupTri& t, QuadInterp& qi, FragmentQuad& q) {
  for (int i = 0; i < 3; ++i) qi.dx[i] = double(t.a[i] * kSubPixel), qi.dy[i] = double(t.b[i] * kSubPixel);
  const FragmentStage& fs = *ctx.fragment;
  // Two passes over the slots: Flat and Smooth ones, then NoPerspective ones, so that the varying Smooth components
  // come first.
  for (const bool smoothPass : {true, false}) {
    for (uint32_t slot = 0; slot < fs.inputCount; ++slot) {
      const FragmentInput& in = fs.inputs[slot];
      if ((in.interpolation == Interpolation::NoPerspective) == smoothPass) continue;
      const uint32_t k = slot * 4;
      if (in.interpolation == Interpolation::Flat) {
        for (uint32_t c = 0; c < 4; ++c) {
          const uint32_t v[4] = {t.flat[k + c], t.flat[k + c], t.flat[k + c], t.flat[k + c]};
          std::memcpy(q.inputs[k + c], v, 16);
        }
        continue;
      }
      const Float4 f0 = load4(t.var[0] + k), d1 = load4(t.var[1] + k) - f0, d2 = load4(t.var[2] + k) - f0;
      for (uint32_t c = 0; c < 4; ++c) {
        if (!(in.componentMask >> c & 1)) continue;
        if (d1[c] == 0 && d2[c] == 0 && !(f0[c] == 0 && std::signbit(f0[c]))) {
          const Float4 v = f0[c] + Float4{};
          std::memcpy(q.inputs[k + c], &v, 16);
          continue;
        }
        qi.component[qi.count++] = {f0[c] + Float4{}, d1[c] + Float4{}, d2[c] + Float4{}, k + c};
      }
    }
    if (smoothPass) qi.smoothCount = qi.count;
  }
  qi.barycentrics = qi.count || fs.readsFragCoord;
  qi.pointCoord = fs.readsPointCoord;
}

// interpolateLane for the four lanes of a single-sampled quad at once (pixel centres; with one sample a pixel is
// covered whole, so centroid inputs interpolate at the centre too): the barycentrics from the exact edge values as
// there, the perspective weights in float across the lanes (one division for four lanes instead of four in double;
// a few ulp apart), and the varying components only (QuadInterp: the rest is in the quad already). All four lanes
// are written (a lane the shader does not run ignores its values), so there is no test per lane.
__attribute__((always_inline)) inline void interpolateQuad(const SetupTri& t, const QuadInterp& qi, FragmentQuad& q,
                                                           int32_t qx, int32_t qy, Float4 fz) {
  // FragCoord's x, y and z (for every shader: a report of a fault names the fragment by them): float(px) / 256 is
  // the pixel index plus 0.5, exactly (|px| < 2^24).
  const Float4 fx = float(qx) + Float4{0.5f, 1.5f, 0.5f, 1.5f}, fy = float(qy) + Float4{0.5f, 0.5f, 1.5f, 1.5f};
  const Float4 xyz[3] = {fx, fy, fz};
  std::memcpy(q.fragCoord, xyz, sizeof xyz);
  if (!qi.pointCoord) {
    // (not read: left as it is)
  } else if (t.isPoint) {
    for (uint32_t l = 0; l < 4; ++l) {
      q.pointCoord[l][0] = 0.5f + (q.fragCoord[0][l] - t.pointX) / t.pointSize;
      q.pointCoord[l][1] = 0.5f + (q.fragCoord[1][l] - t.pointY) / t.pointSize;
    }
  } else {
    std::memset(q.pointCoord, 0, sizeof q.pointCoord);
  }
  if (!qi.barycentrics) return;  // nothing varies and FragCoord is not read: its w is left as it is
  const int64_t px0 = int64_t(qx) * kSubPixel + kCentre, py0 = int64_t(qy) * kSubPixel + kCentre;
  Float4 b[3];  // per vertex, per lane
  for (int i = 0; i < 3; ++i) {
    // The edge's integer values at the four centres, converted once: every value here is below 2^53 in magnitude
    // (coordinates within 2^24 fixed-point units), so the conversions and the sums in double are exact and equal
    // the conversions of the integer sums.
    const double e = double(t.a[i] * px0 + t.b[i] * py0 + t.c[i]);
    const double dx = qi.dx[i], dy = qi.dy[i];
    const Double2 top = Double2{e, e + dx} * t.invArea2, bottom = Double2{e + dy, (e + dx) + dy} * t.invArea2;
    b[i] = __builtin_shufflevector(__builtin_convertvector(top, Float2), __builtin_convertvector(bottom, Float2), 0, 1,
                                   2, 3);
  }
  const Float4 w0 = b[0] * t.invW[0], w1 = b[1] * t.invW[1], w2 = b[2] * t.invW[2];
  const Float4 invW = w0 + w1 + w2;  // FragCoord's w, 1 / w_c
  std::memcpy(q.fragCoord[3], &invW, 16);
  // Lane l's component is f0 + u1[l] d1 + u2[l] d2, the per-lane sum's operations in its order: Smooth components
  // with the perspective-correct weights b_i / w_i normalized ("Polygon Interpolation"; the screen-space ones where
  // the sum is 0, as interpolateLane), NoPerspective ones with the screen-space weights.
  uint32_t i = 0;
  if (qi.smoothCount) {
    const Float4 r = 1.0f / invW;
    const auto zero = invW == 0.0f;
    const Float4 p1 = zero ? b[1] : w1 * r, p2 = zero ? b[2] : w2 * r;
    for (; i < qi.smoothCount; ++i) {
      const QuadInterp::Component& f = qi.component[i];
      const Float4 v = f.f0 + p1 * f.d1 + p2 * f.d2;
      std::memcpy(q.inputs[f.row], &v, 16);
    }
  }
  for (; i < qi.count; ++i) {
    const QuadInterp::Component& f = qi.component[i];
    const Float4 v = f.f0 + b[1] * f.d1 + b[2] * f.d2;
    std::memcpy(q.inputs[f.row], &v, 16);
  }
}

// After the shader: discard, the shader's sample mask, alpha to coverage, the late tests, the color writes.
void finishQuad(const DrawContext& ctx, const SetupTri& t, FragmentQuad& q, float z[4][4], WorkerScratch& scratch) {
  const State& st = *ctx.state;
  const FragmentStage& fs = *ctx.fragment;
  uint32_t passed[4] = {0, 0, 0, 0};  // the samples each lane writes (lanes are distinct pixels: tests first)
  if (ctx.plainFinish) {
    // Nothing between the shader and the colour writes but discard (the tests ran before the shader); a quad with
    // nothing discarded went to its colour writes already (finishQuadInline).
    for (uint32_t l = 0; l < 4; ++l) passed[l] = (q.killed >> l & 1) ? 0 : q.coverage[l];
    if (passed[0] | passed[1] | passed[2] | passed[3]) writeQuadColors(ctx, q, passed);
    return;
  }
  for (uint32_t l = 0; l < 4; ++l) {
    uint32_t c = q.coverage[l];
    if (!c || (q.killed >> l & 1)) continue;
    if (fs.writesSampleMask) c &= q.sampleMaskOut[l];
    if (st.alphaToCoverage && (fs.outputMask & 1)) c &= alphaCoverage(asFloat(q.color[0][3][l]), ctx.samples);
    if (!ctx.earlyTests && c && fs.writesDepth) {
      float d = q.depth[l];
      if (st.depthClamp) d = std::clamp(d, ctx.depthMin, ctx.depthMax);
      for (uint32_t s = 0; s < ctx.samples; ++s) z[s][l] = d;
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
    if (st.alphaToOne && (fs.outputMask & 1)) q.color[0][3][l] = asWord(1.0f);
  }
  writeQuadColors(ctx, q, passed);
}

// What shadeQuad's commonest case reads of the draw, copied once per triangle: read through the context, each would
// be loaded again after every call the quad makes (the calls are opaque, the context could have changed). `fast`:
// one sample, no sample shading, early tests and nothing between the shader and the colour writes but discard
// (plainFinish), a fragment shader, no occlusion count; then a quad is its depths, the early tests, the
// interpolation, the shader and the colour writes.
struct QuadPath {
  bool fast = false;
  decltype(BackEndPlan::depthStencil) depthStencil = nullptr;
  void (*shade)(void* user, FragmentQuad& quad, unsigned worker) = nullptr;
  void* user = nullptr;
  // The one colour attachment's writes; null: writeQuadColors (through finishQuad).
  std::remove_reference_t<decltype(BackEndPlan::color[0])> color0 = nullptr;
  DepthPlane depth;          // one-sample quads' depths (depthQuad)
  bool plainFinish = false;  // DrawContext's
};

QuadPath quadPath(const DrawContext& ctx, const SetupTri& t) {
  QuadPath p;
  p.depth = depthPlane(ctx, t);
  const FragmentStage& fs = *ctx.fragment;
  p.fast =
      ctx.samples == 1 && !ctx.perSample && ctx.earlyTests && ctx.plainFinish && fs.shade && !ctx.draw->samplesPassed;
  p.depthStencil = ctx.backEnd.depthStencil;
  p.shade = fs.shade;
  p.user = fs.user;
  if (ctx.target->colorCount == 1) p.color0 = ctx.backEnd.color[0];
  p.fast = p.fast && (ctx.target->colorCount != 1 || p.color0);
  p.plainFinish = ctx.plainFinish;
  return p;
}

// finishQuad's commonest case without its call (whose frame the other cases need): early tests and nothing
// discarded, so the quad goes to its colour writes with its coverage as it is (it reached the shader with some).
inline void finishQuadInline(const DrawContext& ctx, const SetupTri& t, const QuadPath& path, FragmentQuad& q,
                             float z[4][4], WorkerScratch& scratch) {
  if (!path.plainFinish || q.killed)
    finishQuad(ctx, t, q, z, scratch);
  else if (path.color0)
    path.color0(ctx, 0, q, q.coverage);
  else
    writeQuadColors(ctx, q, q.coverage);
}

// One quad with its per-lane coverage (already limited to the clip rectangle).
void shadeQuad(const DrawContext& ctx, const SetupTri& t, const QuadInterp& qi, const QuadPath& path,
               const DepthRow& zRow, int32_t qx, int32_t qy, uint32_t cov[4], WorkerScratch& scratch, unsigned worker) {
  const FragmentStage& fs = *ctx.fragment;
  const uint32_t any = cov[0] | cov[1] | cov[2] | cov[3];  // (the sample mask is in rasterizeTriangle's `all`)
  if (!any) return;
  alignas(16) float z[4][4];  // z[s][l]: lane l's depth at sample s
  if (path.fast) {
    const Float4 fz = depthQuad(path.depth, zRow, qx, z);
    if (!path.depthStencil(ctx, t.front, qx, qy, cov, z)) return;
    FragmentQuad& q = scratch.quad;
    q.x = qx, q.y = qy;
    q.sampleIndex = 0;
    std::memcpy(q.coverage, cov, sizeof q.coverage);
    interpolateQuad(t, qi, q, qx, qy, fz);
    q.killed = 0;  // (no SampleMask output to preset: plainFinish)
    path.shade(path.user, q, worker);
    // finishQuadInline with plainFinish known (calling it here costs 11 instructions a quad more: callgrind).
    if (q.killed || !path.color0)
      finishQuad(ctx, t, q, z, scratch);
    else
      path.color0(ctx, 0, q, q.coverage);
    return;
  }
  Float4 fz{};
  if (ctx.samples == 1 && !ctx.perSample) {
    fz = depthQuad(path.depth, zRow, qx, z);  // all four lanes: the tests' depths and FragCoord.z (interpolateQuad)
  } else {
    for (uint32_t l = 0; l < 4 && ctx.needsDepth; ++l) {
      if (!cov[l]) continue;
      const int64_t px = int64_t(qx + int32_t(l & 1)) * kSubPixel, py = int64_t(qy + int32_t(l >> 1)) * kSubPixel;
      for (uint32_t s = 0; s < ctx.samples; ++s) z[s][l] = depthAt(ctx, t, px + sampleX(ctx, s), py + sampleY(ctx, s));
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
  FragmentQuad& q = scratch.quad;  // the per-primitive fields set by rasterizeTriangle
  q.x = qx, q.y = qy;
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
      finishQuadInline(ctx, t, path, q, z, scratch);
    }
    return;
  }
  q.sampleIndex = 0;
  for (uint32_t l = 0; l < 4; ++l) q.coverage[l] = cov[l];
  if (ctx.samples == 1) {
    interpolateQuad(t, qi, q, qx, qy, fz);
  } else {
    const uint32_t lanes =
        fs.needsHelpers ? 0xF : ((cov[0] ? 1 : 0) | (cov[1] ? 2 : 0) | (cov[2] ? 4 : 0) | (cov[3] ? 8 : 0));
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
  finishQuadInline(ctx, t, path, q, z, scratch);
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

using U32x4 = uint32_t __attribute__((vector_size(16)));

// The sign bits of the four lanes, lane k at bit k.
inline uint32_t signBits(U32x4 v) {
#if defined(__SSE2__)
  return uint32_t(_mm_movemask_ps(_mm_castsi128_ps(__m128i(v))));
#else
  return (v[0] >> 31) | (v[1] >> 31) << 1 | (v[2] >> 31) << 2 | (v[3] >> 31) << 3;
#endif
}

// A block's coverage as bit masks: row[r] holds pixel row r of the 8x8 block, bit x * S + s for pixel column x and
// sample s (S = 1 or 4, so a row fits in 32 bits). Lanes are sample positions of a row, 2 * S groups of four.
constexpr uint32_t kMaxGroups = 2 * 4;

// Per triangle: what the block loop needs of the edges, computed once.
struct EdgeSetup {
  uint32_t groups;               // 4-lane groups per pixel row: 2 * samples
  bool narrow;                   // every |a| + |b| < 2^20: the edges' values in a block fit in 32 bits (below)
  U32x4 laneOff[3][kMaxGroups];  // per edge, lane j = x * S + s: a * (x * 256 + sx_s) + b * sy_s, modulo 2^32
  uint32_t stepY[3];             // b * 256 modulo 2^32
};

void setupEdges(const DrawContext& ctx, const SetupTri& t, EdgeSetup& es) {
  const uint32_t S = ctx.samples;
  es.groups = 2 * S;
  es.narrow = true;
  for (int i = 0; i < 3; ++i) {
    es.narrow = es.narrow && (t.a[i] < 0 ? -t.a[i] : t.a[i]) + (t.b[i] < 0 ? -t.b[i] : t.b[i]) < (int64_t(1) << 20);
    es.stepY[i] = uint32_t(t.b[i] * kSubPixel);
    for (uint32_t g = 0; g < es.groups; ++g)
      for (uint32_t k = 0; k < 4; ++k) {
        const uint32_t j = g * 4 + k, x = j / S, s = j % S;
        es.laneOff[i][g][k] =
            uint32_t(t.a[i] * (int64_t(x) * kSubPixel + sampleX(ctx, s)) + t.b[i] * int64_t(sampleY(ctx, s)));
      }
  }
}

// Rows r0..r1 of the block at pixel (bx, by), the edges in `active` straddling it (the others hold for all of it).
// A straddling edge's values at the samples of the clipped block lie within [edgeMin, edgeMax], an interval that
// contains 0 and is at most (|a| + |b|) * 8 * 256 < 2^31 long when `narrow`: each fits in a signed 32-bit integer,
// so the sums modulo 2^32 (base + lane offset, stepped by rows) have the exact value's sign. Lanes outside the
// clipped block may wrap; the column mask drops them.
inline void blockMasksNarrow(const SetupTri& t, const EdgeSetup& es, const int* active, int activeCount, int32_t bx,
                             int32_t by, int32_t r0, int32_t r1, uint32_t colMask, uint32_t row[kBlock]) {
  uint32_t base[3];
  for (int n = 0; n < activeCount; ++n) {
    const int i = active[n];
    base[n] = uint32_t(t.a[i] * int64_t(bx) * kSubPixel + t.b[i] * int64_t(by + r0) * kSubPixel + t.c[i] + t.cBias[i]);
  }
  for (int32_t r = r0; r <= r1; ++r) {
    uint32_t outside = 0;  // lanes where some edge is negative
    for (uint32_t g = 0; g < es.groups; ++g) {
      U32x4 v = es.laneOff[active[0]][g] + base[0];
      for (int n = 1; n < activeCount; ++n) v |= es.laneOff[active[n]][g] + base[n];
      outside |= signBits(v) << (4 * g);
    }
    row[r] = colMask & ~outside;
    for (int n = 0; n < activeCount; ++n) base[n] += es.stepY[active[n]];
  }
}

// The same in 64-bit arithmetic, lane by lane (triangles with edges longer than 4096 pixels).
inline void blockMasksWide(const DrawContext& ctx, const SetupTri& t, const int* active, int activeCount, int32_t bx,
                           int32_t by, int32_t r0, int32_t r1, uint32_t colMask, uint32_t row[kBlock]) {
  const uint32_t S = ctx.samples;
  for (int32_t r = r0; r <= r1; ++r) {
    uint32_t inside = 0;
    for (uint32_t j = 0; j < kBlock * S; ++j) {
      const int64_t px = int64_t(bx + int32_t(j / S)) * kSubPixel + sampleX(ctx, j % S);
      const int64_t py = int64_t(by + r) * kSubPixel + sampleY(ctx, j % S);
      int64_t e = 0;
      for (int n = 0; n < activeCount; ++n) {
        const int i = active[n];
        e |= t.a[i] * px + t.b[i] * py + t.c[i] + t.cBias[i];
      }
      inside |= uint32_t(e >= 0) << j;
    }
    row[r] = colMask & inside;
  }
}

void rasterizeTriangle(const DrawContext& ctx, const SetupTri& t, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                       WorkerScratch& scratch, unsigned worker) {
  // A quad's lanes' samples: the covered ones the sample mask keeps ("Sample Mask": applied before the tests).
  const uint32_t S = ctx.samples, all = ctx.allSamples & ctx.state->sampleMask, pairMask = (1u << (2 * S)) - 1;
  EdgeSetup es;
  setupEdges(ctx, t, es);
  // What is the same for every quad of the triangle (shadeQuad sets the rest).
  FragmentQuad& q = scratch.quad;
  QuadInterp qi;  // one-sample quads' interpolation (shadeQuad), and the inputs that are the same for all of them
  if (S == 1 && !ctx.perSample && ctx.fragment->shade) setupQuadInterp(ctx, t, qi, q);
  const QuadPath path = quadPath(ctx, t);
  q.frontFacing = t.front;
  q.primitiveId = t.primitiveId;
  q.viewIndex = ctx.viewIndex;
  q.layer = ctx.layer;
  q.primitive = &t;  // for interpolateAt
  q.drawContext = &ctx;
  const uint32_t fullRow = uint32_t((uint64_t(1) << (kBlock * S)) - 1);  // a block row's mask, every sample
  const int32_t bx0 = x0 & ~(kBlock - 1), by0 = y0 & ~(kBlock - 1);
  for (int32_t by = by0; by <= y1; by += kBlock) {
    for (int32_t bx = bx0; bx <= x1; bx += kBlock) {
      // The block, clipped to the triangle's rectangle: skip it when an edge excludes all of it; the edges that
      // include all of it need no test per sample.
      const int32_t rx0 = std::max(bx, x0), ry0 = std::max(by, y0);
      const int32_t rx1 = std::min(bx + kBlock - 1, x1), ry1 = std::min(by + kBlock - 1, y1);
      int active[3], activeCount = 0;
      bool reject = false;
      for (int i = 0; i < 3 && !reject; ++i) {
        reject = edgeMax(t, i, rx0, ry0, rx1 + 1, ry1 + 1) < 0;
        if (edgeMin(t, i, rx0, ry0, rx1 + 1, ry1 + 1) < 0) active[activeCount++] = i;
      }
      if (reject) continue;
      // Pixels outside the triangle's rectangle (the clip rectangle included) are not covered.
      const uint32_t colMask =
          uint32_t(((uint64_t(1) << ((rx1 - bx + 1) * S)) - 1) & ~((uint64_t(1) << ((rx0 - bx) * S)) - 1));
      const int32_t r0 = ry0 - by, r1 = ry1 - by;
      uint32_t row[kBlock] = {};
      if (!activeCount) {
        for (int32_t r = r0; r <= r1; ++r) row[r] = colMask;
      } else if (es.narrow) {
        blockMasksNarrow(t, es, active, activeCount, bx, by, r0, r1, colMask, row);
      } else {
        blockMasksWide(ctx, t, active, activeCount, bx, by, r0, r1, colMask, row);
      }
      // The quads in row order, as the per-fragment operations need (primitive order per pixel is kept anyway;
      // the same order keeps images identical to the per-quad loop this replaced).
      // A block inside the triangle and the clip rectangle (most of a large triangle's): every lane of every quad
      // covers the samples `all` keeps, with no masks to take apart.
      const bool whole = !activeCount && r0 == 0 && r1 == kBlock - 1 && colMask == fullRow;
      for (int32_t r = r0 & ~1; r <= r1; r += 2) {
        const uint32_t m0 = row[r], m1 = row[r + 1];
        const uint32_t any = m0 | m1;
        if (!any) continue;  // an empty row of quads at once
        const DepthRow zRow = depthRow(path.depth, by + r);
        for (uint32_t c = 0; c < kBlock / 2; ++c) {
          const uint32_t shift = 2 * c * S;
          uint32_t cov[4] = {all, all, all, all};
          if (!whole) {
            if (!((any >> shift) & pairMask)) continue;
            cov[0] = (m0 >> shift) & all, cov[1] = (m0 >> (shift + S)) & all;
            cov[2] = (m1 >> shift) & all, cov[3] = (m1 >> (shift + S)) & all;
          }
          shadeQuad(ctx, t, qi, path, zRow, bx + int32_t(2 * c), by + r, cov, scratch, worker);
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
