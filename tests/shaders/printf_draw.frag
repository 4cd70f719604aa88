#version 460
#extension GL_EXT_debug_printf : require
// The fragments of the target's top-left 2 x 2 pixels print their coordinates (tests/e2e/shader_debug_test.cpp).
layout(location = 0) out vec4 color;
void main() {
  if (gl_FragCoord.x < 2.0 && gl_FragCoord.y < 2.0) debugPrintfEXT("fragment %v2f", gl_FragCoord.xy);
  color = vec4(0.0, 1.0, 0.0, 1.0);
}
