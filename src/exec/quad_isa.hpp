// The hand-vectorized kernels compiled twice, for the baseline x86-64 target and for AVX2 (the quad sampler,
// runtime/quad_sampling.cpp; the raster's tile loop, raster/tile.cpp, and its 8-bit UNorm colour writes,
// raster/backend.cpp): whether the CPU runs the AVX2 copies, whether they run by default, and the markers around an
// AVX2 copy's code. Each AVX2 copy performs the same operations as its baseline one without FMA (the target has none,
// so nothing is contracted): the same bits.
#pragma once

namespace vkrt::exec {

// Whether the CPU has AVX2; F16C (the half-float conversions, which the raster's float16 colour writes' AVX2 copy
// also takes).
bool hostHasAvx2();
bool hostHasF16c();
// Whether the AVX2 copies run unless a test chooses: where the CPU has AVX2 and the environment's VKRT_QUAD_ISA is
// not "baseline".
bool quadAvx2ByDefault();

}  // namespace vkrt::exec

// VKRT_AVX2_BEGIN ... VKRT_AVX2_END: the functions between them are compiled for AVX2 (x86-64 only; the caller
// chooses them at run time where hostHasAvx2()).
#if defined(__clang__)
#define VKRT_AVX2_BEGIN _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define VKRT_AVX2_END _Pragma("clang attribute pop")
#else
#define VKRT_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define VKRT_AVX2_END _Pragma("GCC pop_options")
#endif
