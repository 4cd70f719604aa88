// Reads two inline uniform blocks (tests/e2e/inline_uniform_block_test.cpp): binding 0 (64 bytes) and binding 1
// (32 bytes) of set 0 are uniform blocks to the shader. Invocation i < 24 stores 32-bit word i of their bytes, in
// order (binding 0's 16 words, then binding 1's 8), into the storage buffer at binding 2.
#version 450
layout(local_size_x = 32) in;

layout(set = 0, binding = 0) uniform First { uvec4 v[4]; } first;
layout(set = 0, binding = 1) uniform Second { uvec4 v[2]; } second;
layout(set = 0, binding = 2, std430) buffer Out { uint o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < 16u)
    o[i] = first.v[i / 4u][i % 4u];
  else if (i < 24u)
    o[i] = second.v[(i - 16u) / 4u][(i - 16u) % 4u];
}
