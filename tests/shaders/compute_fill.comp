#version 460
// Fills a storage buffer with (index * scale + bias); used by the shader-module tests.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) buffer Out { uint values[]; } outBuf;
layout(push_constant) uniform Push { uint scale; uint bias; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < outBuf.values.length()) outBuf.values[i] = i * pc.scale + pc.bias;
}
