#version 460
// SAXPY without the shader's own bounds test: every access past a buffer's range relies on the compiler's
// robustness (reads give zero, writes are dropped). The loop vkrt_group runs over this workgroup is the
// vectorized one, with masked loads and stores; used by the per-workgroup entry tests.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) readonly buffer X { float x[]; };
layout(set = 0, binding = 1, std430) buffer Y { float y[]; };
layout(push_constant) uniform Push { float a; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  y[i] = pc.a * x[i] + y[i];
}
