#version 460
// C = A * B for n x n row-major float matrices, one invocation per element of C.
layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0, std430) readonly buffer A { float a[]; };
layout(set = 0, binding = 1, std430) readonly buffer B { float b[]; };
layout(set = 0, binding = 2, std430) writeonly buffer C { float c[]; };
layout(push_constant) uniform Push { uint n; } pc;
void main() {
  uint col = gl_GlobalInvocationID.x, row = gl_GlobalInvocationID.y;
  if (row >= pc.n || col >= pc.n) return;
  float sum = 0.0;
  for (uint k = 0u; k < pc.n; ++k) sum += a[row * pc.n + k] * b[k * pc.n + col];
  c[row * pc.n + col] = sum;
}
