#version 450
// A rectangle covering the whole viewport at depth `z` (push constant; tests/e2e/input_attachment_test.cpp).
layout(push_constant) uniform P { float z; } pc;
void main() {
  int i = gl_VertexIndex;
  float cx = (i == 1 || i == 3 || i == 4) ? 1.0 : -1.0;
  float cy = (i == 2 || i == 4 || i == 5) ? 1.0 : -1.0;
  gl_Position = vec4(cx, cy, pc.z, 1.0);
}
