#version 460
#extension GL_EXT_debug_printf : require
// A triangle covering the target from gl_VertexIndex alone (no vertex input); each vertex prints its index and
// position (tests/e2e/shader_debug_test.cpp).
void main() {
  vec2 p = vec2(gl_VertexIndex == 1 ? 3.0 : -1.0, gl_VertexIndex == 2 ? 3.0 : -1.0);
  debugPrintfEXT("vertex %d at %v2f", gl_VertexIndex, p);
  gl_Position = vec4(p, 0.0, 1.0);
}
