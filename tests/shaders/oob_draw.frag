#version 450
// Each fragment of a 32 x 32 target stores its index + 1 at its index (y * 32 + x) in `result`, whose range the test
// chooses (tests/e2e/shader_debug_test.cpp: ShaderDebugDrawTest.FragmentStoreOutOfBoundsNamesTheFragment).
layout(set = 0, binding = 0, std430) buffer Out { uint v[]; } result;
layout(location = 0) out vec4 color;
void main() {
  uint i = uint(gl_FragCoord.y) * 32u + uint(gl_FragCoord.x);
  result.v[i] = i + 1u;
  color = vec4(0.0, 1.0, 0.0, 1.0);
}
