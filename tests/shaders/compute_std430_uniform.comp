#version 450
// A std430 uniform block (float array of stride 4): valid with uniformBufferStandardLayout.
#extension GL_EXT_scalar_block_layout : require
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) uniform U {
  float f[8];  // 0, stride 4
  uvec2 p;     // 32
} u;
layout(set = 0, binding = 1, std430) writeonly buffer Out { float o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  o[i] = u.f[i] * float(u.p.x) + float(u.p.y);
}
