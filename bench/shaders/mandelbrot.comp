#version 460
// Iteration counts of the Mandelbrot set over [-2, 1] x [-1.5, 1.5], size x size pixels.
layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint iterations[]; };
layout(push_constant) uniform Push { uint size; uint maxIterations; } pc;
void main() {
  uint px = gl_GlobalInvocationID.x, py = gl_GlobalInvocationID.y;
  if (px >= pc.size || py >= pc.size) return;
  float cx = -2.0 + 3.0 * float(px) / float(pc.size);
  float cy = -1.5 + 3.0 * float(py) / float(pc.size);
  float x = 0.0, y = 0.0;
  uint i = 0u;
  while (i < pc.maxIterations && x * x + y * y <= 4.0) {
    float t = x * x - y * y + cx;
    y = 2.0 * x * y + cy;
    x = t;
    ++i;
  }
  iterations[py * pc.size + px] = i;
}
