#version 460
// An out-of-bounds write, compiled with -g (tests/e2e/shader_debug_test.cpp): line 7 stores past the buffer's end.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) buffer Out { uint o[]; } result;
void main() {
  uint i = gl_GlobalInvocationID.x;
  result.o[i + 100u] = i;
}
