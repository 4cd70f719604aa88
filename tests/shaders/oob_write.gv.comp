#version 460
// An out-of-bounds write compiled with glslangValidator -gV: NonSemantic.Shader.DebugInfo.100 line information,
// not OpLine (tests/e2e/shader_debug_test.cpp). Line 9 stores past the buffer's end.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) buffer Out { uint o[]; } result;
void main() {
  uint i = gl_GlobalInvocationID.x;
  uint j = i + 100u;
  result.o[j] = i;
}
