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

#include "exec/quad_isa.hpp"
#include "raster/internal.hpp"

namespace vkrt::raster::detail {

// The tile loop twice (tile_kernels.inc): for the baseline target, and for AVX2 (no FMA: the same operations, rounded
// alike, so the same bytes; the VEX forms and four doubles a vector take fewer instructions a quad). Each copy in an
// anonymous namespace of its own: nothing of the AVX2 copy has external linkage, so none of it can stand in for
// baseline code on a CPU without AVX2.
namespace baseline {
namespace {
#include "raster/tile_kernels.inc"
}  // namespace
}  // namespace baseline

#if defined(__x86_64__)
VKRT_AVX2_BEGIN
namespace avx2 {
namespace {
#include "raster/tile_kernels.inc"
}  // namespace
}  // namespace avx2
VKRT_AVX2_END
#endif

void rasterizeTile(const DrawContext& ctx, const SetupTri* const* tris, size_t count, int32_t tileX, int32_t tileY,
                   WorkerScratch& scratch, unsigned worker) {
#if defined(__x86_64__)
  if (quadWritesAvx2()) return avx2::rasterizeTileCopy(ctx, tris, count, tileX, tileY, scratch, worker);
#endif
  baseline::rasterizeTileCopy(ctx, tris, count, tileX, tileY, scratch, worker);
}

}  // namespace vkrt::raster::detail
