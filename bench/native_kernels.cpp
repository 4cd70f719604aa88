#include "native_kernels.hpp"

namespace vkrt::bench {

void saxpy(float a, const float* x, float* y, uint32_t n) {
  for (uint32_t i = 0; i < n; ++i) y[i] = a * x[i] + y[i];
}

void matmul(const float* a, const float* b, float* c, uint32_t n) {
  for (uint32_t row = 0; row < n; ++row)
    for (uint32_t col = 0; col < n; ++col) {
      float sum = 0.0f;
      for (uint32_t k = 0; k < n; ++k) sum += a[row * n + k] * b[k * n + col];
      c[row * n + col] = sum;
    }
}

void mandelbrot(uint32_t* iterations, uint32_t size, uint32_t maxIterations) {
  for (uint32_t py = 0; py < size; ++py)
    for (uint32_t px = 0; px < size; ++px) {
      float cx = -2.0f + 3.0f * float(px) / float(size);
      float cy = -1.5f + 3.0f * float(py) / float(size);
      float x = 0.0f, y = 0.0f;
      uint32_t i = 0;
      while (i < maxIterations && x * x + y * y <= 4.0f) {
        float t = x * x - y * y + cx;
        y = 2.0f * x * y + cy;
        x = t;
        ++i;
      }
      iterations[py * size + px] = i;
    }
}

}  // namespace vkrt::bench
