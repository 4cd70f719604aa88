// The benchmark's kernels written in C++ (compiled with -O2 in native_kernels.cpp), the same algorithms as
// bench/shaders/*.comp, single-threaded.
#pragma once

#include <cstdint>

namespace vkrt::bench {

void saxpy(float a, const float* x, float* y, uint32_t n);
void matmul(const float* a, const float* b, float* c, uint32_t n);
void mandelbrot(uint32_t* iterations, uint32_t size, uint32_t maxIterations);

}  // namespace vkrt::bench
