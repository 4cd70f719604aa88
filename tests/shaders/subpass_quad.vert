#version 450
// Six vertices of a rectangle covering the whole viewport (tests/e2e/input_attachment_test.cpp).
void main() {
  int i = gl_VertexIndex;
  float cx = (i == 1 || i == 3 || i == 4) ? 1.0 : -1.0;
  float cy = (i == 2 || i == 4 || i == 5) ? 1.0 : -1.0;
  gl_Position = vec4(cx, cy, 0.0, 1.0);
}
