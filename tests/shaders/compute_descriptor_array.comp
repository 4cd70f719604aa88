#version 460
// An array of storage buffer descriptors indexed with constants, and the runtime array length of one of them.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer Bufs { uint v[]; } bufs[3];
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint r[]; } outp;
void main() {
  uint i = gl_GlobalInvocationID.x;
  outp.r[i] = bufs[0].v[i] + 10u * bufs[1].v[i] + 100u * bufs[2].v[i] + 1000u * uint(bufs[2].v.length());
}
