// The rasterizer's internal stages and the records they pass on (see raster.hpp for the contract of draw()):
//   draw.cpp      vertex shading, primitive assembly, binning, the per-tile dispatch
//   setup.cpp     clipping, the viewport transform, culling, triangle/line/point setup into SetupTri records
//   tile.cpp      coverage of one tile, 2x2 quads, interpolation, the fragment shader call (tile_kernels.inc, twice)
//   backend.cpp   the per-fragment operations (depth bounds, stencil, depth, blending, logic op, write masks)
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "raster/raster.hpp"

namespace vkrt::raster::detail {

inline constexpr int32_t kSubPixel = 1 << kSubPixelBits;  // fixed-point units per pixel
inline constexpr int32_t kTileSize = 64;                  // pixels; even, so that 2x2 quads never straddle tiles
// Sample positions in fixed-point units within the pixel: the centre for 1 sample, the standard 4-sample pattern.
inline constexpr int32_t kSampleX4[4] = {96, 224, 32, 160};
inline constexpr int32_t kSampleY4[4] = {32, 96, 160, 224};
inline constexpr int32_t kCentre = kSubPixel / 2;

inline float asFloat(uint32_t w) { return std::bit_cast<float>(w); }
inline uint32_t asWord(float f) { return std::bit_cast<uint32_t>(f); }

// Bump allocator for a stage's per-draw storage: blocks of fixed size, pointers stay valid until destruction.
class Arena {
 public:
  uint32_t* alloc(size_t words) {
    if (used_ + words > blockWords_ || blocks_.empty()) {
      size_t size = words > kBlockWords ? words : kBlockWords;
      blocks_.push_back(std::make_unique<uint32_t[]>(size));
      blockWords_ = size;
      used_ = 0;
    }
    uint32_t* p = blocks_.back().get() + used_;
    used_ += words;
    return p;
  }

 private:
  static constexpr size_t kBlockWords = 16384;
  std::vector<std::unique_ptr<uint32_t[]>> blocks_;
  size_t blockWords_ = 0, used_ = 0;
};

// A primitive ready to rasterize: a triangle in fixed point (points and lines arrive as two triangles each).
// Edge i is opposite vertex i; E_i(p) = a*px + b*py + c in fixed-point units is > 0 inside, and cBias folds in the
// top-left rule: a sample is covered when every E_i(p) + cBias_i >= 0 (bias -1 on edges that are neither top nor
// left, so that a sample exactly on them is not covered).
struct SetupTri {
  int64_t a[3], b[3], c[3];
  int64_t area2;                   // E_0 + E_1 + E_2 (twice the area in fixed-point units squared), > 0
  double invArea2;                 // 1 / area2
  int64_t cBias[3];                // 0 or -1
  double zA, zB, zC;               // z_f = zA * x + zB * y + zC, x and y in pixels, bias included (before clamping)
  float invW[3];                   // 1 / w_c per vertex
  const uint32_t* var[3];          // the vertices' varyings (varyingCount * 4 words)
  const uint32_t* flat;            // the provoking vertex's varyings
  int32_t minX, minY, maxX, maxY;  // covered pixel bounds, inclusive, within the draw's clip rectangle
  uint32_t primitiveId;
  bool front;
  bool isPoint;
  float pointX, pointY, pointSize;  // points: centre and side in framebuffer coordinates (for PointCoord)
};

struct DrawContext;

// The per-fragment operations of a whole 2x2 quad (lane l is pixel (qx + (l & 1), qy + (l >> 1))), chosen once per
// draw by planBackEnd from the attachments' formats and the state: specialised paths for the common cases (one
// sample, D32 depth alone, 8-bit UNorm colour), the per-lane general path otherwise. Both give the same bytes.
struct BackEndPlan {
  // Depth bounds, stencil and depth tests: clears the samples of cov[l] that fail, updates the attachment, returns
  // the union of what passed. z[s][l] is lane l's depth at sample s (sample-major: a one-sample quad's four depths are
  // one row).
  uint32_t (*depthStencil)(const DrawContext& ctx, bool front, int32_t qx, int32_t qy, uint32_t cov[4],
                           const float (*z)[4]) = nullptr;
  // Colour attachment i's writes (blend, logic op, write mask) of each lane's samples in cov; null: nothing to write.
  void (*color[kMaxColorAttachments])(const DrawContext& ctx, uint32_t i, const FragmentQuad& q,
                                      const uint32_t cov[4]) = {};
  uint32_t quadPaths = 0;  // which took a specialised path: bit 0 depth/stencil, bit 1 + i colour attachment i (tests)
};

// What every stage of one draw (one view, one batch of instances) shares. Read-only while tiles run.
struct DrawContext {
  const Target* target;
  const State* state;
  const Draw* draw;
  const VertexStage* vertex;
  const FragmentStage* fragment;
  uint32_t varyingWords;                   // varyingCount * 4
  uint32_t samples;                        // 1 or 4
  uint32_t allSamples;                     // (1 << samples) - 1
  int32_t clipX0, clipY0, clipX1, clipY1;  // render area & scissor & attachments, pixels, [x0, x1)
  uint32_t viewIndex, layer;
  bool perSample;                    // shade once per covered sample
  bool earlyTests;                   // depth/stencil before the shader
  bool hasSmooth, hasNoPerspective;  // any input of that kind
  bool needsDepth;   // some test reads the fragment's depth (else the per-sample depths are not computed)
  bool plainFinish;  // early tests, no shader sample mask, alpha to coverage or alpha to one: after the shader only
                     // discard applies before the colour writes
  // Viewport 0: x_f = x_ndc * scaleX + offX, likewise y; z_f = z_ndc * scaleZ + offZ.
  float scaleX, offX, scaleY, offY, scaleZ, offZ;
  float depthMin, depthMax;  // the clamp range of fragment depth: viewport range with depth clamp, else [0, 1]
  float guardX, guardY;      // |x_c| <= guardX * w_c keeps framebuffer x within the fixed-point range
  double depthR;             // the minimum resolvable difference r of fixed-point depth (0 for float depth)
  BackEndPlan backEnd;       // planBackEnd
};

// Per-worker scratch of the tile stage. A cache line of its own: samplesPassed is written per quad, and next to the
// following worker's quad it made every quad of two workers contend for one line (false sharing).
struct alignas(64) WorkerScratch {
  FragmentQuad quad;
  uint64_t samplesPassed = 0;  // this worker's count for Draw::samplesPassed, added at the end of each tile
};

// setup.cpp: clips and sets up one assembled primitive (vertex pointers in primitive order, the provoking one
// given), appending zero or more SetupTri to `out`; synthesized vertices' varyings live in `arena`.
struct AssembledPrim {
  const ShadedVertex* v[3];
  uint32_t count;      // 1, 2 or 3
  uint32_t provoking;  // index into v
  uint32_t primitiveId;
};
void setupPrimitive(const DrawContext& ctx, const AssembledPrim& prim, std::vector<SetupTri>& out, Arena& arena);

// tile.cpp: rasterizes `tris` (in draw order) within the tile whose top-left pixel is (tileX, tileY).
void rasterizeTile(const DrawContext& ctx, const SetupTri* const* tris, size_t count, int32_t tileX, int32_t tileY,
                   WorkerScratch& scratch, unsigned worker);

// backend.cpp: the per-fragment operations.
// Depth at a sample, clamped and then converted to the attachment's representation and back (as stored).
// Runs depth bounds, stencil and depth tests for lane `lane`'s samples in `coverage` at pixel (x, y), with the
// per-sample depths `z[s]`, updating the attachment; returns the samples that passed.
uint32_t depthStencilTests(const DrawContext& ctx, bool front, int32_t x, int32_t y, uint32_t coverage, const float* z);
// Chooses ctx.backEnd (once per draw, after the rest of the context is set).
void planBackEnd(DrawContext& ctx);
// Whether planBackEnd may choose the specialised quad paths (tests turn them off to compare with the general path).
void setQuadPaths(bool enabled);
// The quad writes' 8-bit sRGB encode (backend.cpp srgbEncode4) of in[0..n), n a multiple of 4 (the tests).
void encodeSrgb8Quads(const float* in, uint32_t* out, size_t n);
// ... and the AVX2 copy's (srgbEncode8) of in[0..n), n a multiple of 8; false where the CPU has no AVX2.
bool encodeSrgb8Octets(const float* in, uint32_t* out, size_t n);
// Whether planBackEnd chooses the AVX2 copy of the 8-bit UNorm colour quad path, and rasterizeTile the AVX2 copy of
// the tile loop (each the same bytes as its baseline copy; by default where the CPU has AVX2, unless
// VKRT_QUAD_ISA=baseline). False, changing nothing, when asked for AVX2 on a CPU without it (the tests).
bool setQuadWritesAvx2(bool enabled);
bool quadWritesAvx2();
// Writes the quad's color outputs to each lane's samples in `coverage` (blend, logic op, write masks); lane l is
// pixel (quad.x + (l & 1), quad.y + (l >> 1)).
inline void writeQuadColors(const DrawContext& ctx, const FragmentQuad& quad, const uint32_t coverage[4]) {
  for (uint32_t i = 0; i < ctx.target->colorCount; ++i)
    if (ctx.backEnd.color[i]) ctx.backEnd.color[i](ctx, i, quad, coverage);
}
// Alpha to coverage: the samples alpha keeps.
uint32_t alphaCoverage(float alpha, uint32_t samples);

}  // namespace vkrt::raster::detail
