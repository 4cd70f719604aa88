#version 460
// A descriptor array indexed past the bound descriptors (tests/spirv/shader_debug_test.cpp): binding 0 has four
// buffers in the shader; the push constant picks one.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer In { uint v; } bufs[4];
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint o[]; };
layout(push_constant) uniform Push { uint index; };

void main() {
  o[gl_GlobalInvocationID.x] = bufs[index].v;
}
