// The quad sampler's vector fast path (quad_sampling.hpp): the four lanes of vkrt_image_sample_grad_quad in the four
// elements of each vector, for the level of detail, the coordinates, the level selection, the texel addressing and
// the filter. Each step repeats the per-lane fast path's (image_functions.cpp: lodOfDerivatives, biasedLod,
// fastAtLod, fastSample, fastCoord, fixedCoord, fastFilterLevel) operation for operation, so every lane's result is
// the same bits as that lane's vkrt_image_sample_grad; where the per-lane path takes two shapes, the vector path
// takes the one that gives the other's result exactly:
//   - NEAREST is LINEAR with both texels of each axis the nearest one and weights 0: t + 0 (t - t) is t.
//   - one level (mipmap NEAREST, or a whole level of detail) is two levels, the same twice, at weight 0: a (1 - 0) +
//     b 0 is a, for the texels' values are never negative (no -0 either).
// Lanes may select different levels and filters; only the texel loads are per lane (SSE2 has no gather). Where any
// lane blends two levels, both levels are filtered in one pass of eight elements (the four lanes at the first level,
// then at the second: the same operations on each element, so the same bits as two passes). A LINEAR pair whose
// second texel follows the first in the row (every lane's, away from a REPEAT seam or a CLAMP edge) comes from one
// 8-byte load; NEAREST loads its one texel once. The sRGB decoding, the address modes and the filters (both NEAREST,
// both LINEAR, or by lane) are template parameters, chosen once per call (sampleQuadFast).
//
// One case has a path of its own (sampleQuadUniform): a view whose lanes all have the same level of detail and layer,
// which is every quad of a fragment shader's implicit-LOD sampling (coarse derivatives: the quad's level of detail).
// There the clamps and the level selection are scalars. UNorm levels are filtered in integers: the texel pairs of two
// lanes interleaved by component in one register, one multiply-add of 16-bit pairs per row for the horizontal
// weights, the vertical ones in float (exact: at most 24 significant bits), so the same bits as the float lerps
// elsewhere, which are exact with 8-bit weights (kSubTexelBits). sRGB levels take the tables' floats and the per-lane
// path's lerps, two lanes to a vector of eight. A raster frame's sampling takes this path.
#include "runtime/quad_sampling.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#if defined(__SSE2__)
#include <immintrin.h>  // SSE's MOVMSKPS (laneBits) and, in the AVX2 copy, AVX2's shuffles (quadTexelPairs)
#endif

#include "exec/quad_isa.hpp"
#include "runtime/lod_log2.hpp"

namespace vkrt {

// The kernels twice (quad_sampling_kernels.inc): for the baseline target, and for AVX2 (no FMA: the same operations,
// rounded alike, so that both give every lane the same bits; SamplerFastPath's tests compare them). Each copy in an
// anonymous namespace of its own: nothing of the AVX2 copy has external linkage, so none of it can stand in for
// baseline code on a CPU without AVX2.
namespace baseline {
namespace {
#include "runtime/quad_sampling_kernels.inc"
}  // namespace
}  // namespace baseline

#if defined(__x86_64__)
VKRT_AVX2_BEGIN
namespace avx2 {
namespace {
#define VKRT_QUAD_AVX2 1  // the kernels may use AVX2 intrinsics
#include "runtime/quad_sampling_kernels.inc"
#undef VKRT_QUAD_AVX2
}  // namespace
}  // namespace avx2
VKRT_AVX2_END
#endif

namespace {

// Which copy sampleQuadFast runs: AVX2 where the CPU has it, unless VKRT_QUAD_ISA=baseline; setQuadSamplingIsa
// (the tests) changes it.
std::atomic<QuadIsa> gQuadIsa = exec::quadAvx2ByDefault() ? QuadIsa::Avx2 : QuadIsa::Baseline;

}  // namespace

QuadIsa quadSamplingIsa() { return gQuadIsa.load(std::memory_order_relaxed); }

bool setQuadSamplingIsa(QuadIsa isa) {
  if (isa == QuadIsa::Avx2 && !exec::hostHasAvx2()) return false;
  gQuadIsa.store(isa, std::memory_order_relaxed);
  return true;
}

// The variant of the view's decoding, the sampler's address modes and filters.
uint32_t sampleQuadFast(const QuadView& v, const QuadSampler& s, const float coord[16], const float ddx[16],
                        const float ddy[16], const float bias[4], uint32_t lanes, uint32_t out[16], float lod[4]) {
  const unsigned filter = s.magLinear != s.minLinear ? baseline::kMixed
                          : s.magLinear              ? baseline::kLinear
                                                     : baseline::kNearest;
  const unsigned index = unsigned(v.srgb) * 12 + unsigned(s.repeatU) * 6 + unsigned(s.repeatV) * 3 + filter;
#if defined(__x86_64__)
  if (quadSamplingIsa() == QuadIsa::Avx2) return avx2::kVariants[index](v, s, coord, ddx, ddy, bias, lanes, out, lod);
#endif
  return baseline::kVariants[index](v, s, coord, ddx, ddy, bias, lanes, out, lod);
}

}  // namespace vkrt
