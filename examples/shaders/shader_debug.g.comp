#version 460
#extension GL_EXT_debug_printf : enable
// examples/shader_debug.cpp: eight invocations print a line each and store their square; the last one also stores
// one element past the buffer's end (compiled with -g, so vkrt's report names this file and line 11).
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) buffer Squares { uint squares[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  debugPrintfEXT("invocation %u: %u squared is %u", i, i, i * i);
  squares[i] = i * i;
  if (i == 7u) squares[i + 1u] = 0u;
}
