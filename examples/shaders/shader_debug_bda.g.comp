#version 460
#extension GL_EXT_buffer_reference : require
// examples/shader_debug.cpp --bda: eight invocations store their square through a device address (a
// buffer_reference pointer in a push constant); the last one also stores one element past the 32-byte buffer
// (compiled with -g: with VKRT_SHADER_CHECKS=bda, vkrt's report names this file and line 12).
layout(local_size_x = 8) in;
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint data[]; };
layout(push_constant) uniform PC { Words squares; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  squares.data[i] = i * i;
  if (i == 7u) squares.data[i + 1u] = 0u;
}
