#version 460
// A read at a shifted index (tests/e2e/shader_debug_test.cpp, tests/spirv/shader_debug_test.cpp), compiled without
// debug information: out of bounds when the push constant shifts it past the input buffer, in bounds when it is 0.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer In { uint a[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint o[]; };
layout(push_constant) uniform Push { uint shift; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  o[i] = a[i + shift];
}
