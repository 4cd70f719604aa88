#version 460
// Sums a uniform array into a storage buffer; a second real module for the shader-module tests.
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform In { uvec4 v[4]; } inBuf;
layout(set = 0, binding = 1) buffer Out { uint sum; } outBuf;
void main() {
  uint s = 0;
  for (int i = 0; i < 4; ++i) s += inBuf.v[i].x + inBuf.v[i].y + inBuf.v[i].z + inBuf.v[i].w;
  outBuf.sum = s;
}
