#version 460
// C = A * B for n x n row-major float matrices (n a multiple of 16), one invocation per element of C, through
// workgroup memory: each 16 x 16 workgroup stages a tile of A and one of B per step, with a barrier after the loads
// and one after the products (the usual shared-memory form of matmul.comp).
layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0, std430) readonly buffer A { float a[]; };
layout(set = 0, binding = 1, std430) readonly buffer B { float b[]; };
layout(set = 0, binding = 2, std430) writeonly buffer C { float c[]; };
layout(push_constant) uniform Push { uint n; } pc;
shared float tileA[16][16];
shared float tileB[16][16];
void main() {
  uint tx = gl_LocalInvocationID.x, ty = gl_LocalInvocationID.y;
  uint col = gl_GlobalInvocationID.x, row = gl_GlobalInvocationID.y;
  float sum = 0.0;
  for (uint t = 0u; t < pc.n; t += 16u) {
    tileA[ty][tx] = a[row * pc.n + t + tx];
    tileB[ty][tx] = b[(t + ty) * pc.n + col];
    barrier();
    for (uint k = 0u; k < 16u; ++k) sum += tileA[ty][k] * tileB[k][tx];
    barrier();
  }
  c[row * pc.n + col] = sum;
}
