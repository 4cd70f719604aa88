#version 460
// A uniform address read by some invocations only (tests/spirv/shader_debug_test.cpp): invocations 2 and 3 read
// a[shift], the same element; out of bounds when the push constant says so. The SPMD path reads it once for its
// batch (a uniform access), and its report must name an invocation that made it: 2, the first.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer In { uint a[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint o[]; };
layout(push_constant) uniform Push { uint shift; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint v = 7u;
  if (i >= 2u) v = a[shift];
  o[i] = v;
}
