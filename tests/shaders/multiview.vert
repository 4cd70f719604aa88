#version 450
#extension GL_EXT_multiview : require
// Multiview (tests/e2e/multiview_test.cpp): six vertices of a rectangle spanning the full height, its horizontal
// extent chosen by gl_ViewIndex (view v covers NDC x in [-1 + v, v], the left or right half for views 0 and 1); the
// blue channel also depends on the view index, so the vertex stage's ViewIndex is checked too.
layout(location = 0) flat out vec4 vColor;
void main() {
  int i = gl_VertexIndex;
  float cx = (i == 1 || i == 3 || i == 4) ? 1.0 : 0.0;
  float cy = (i == 2 || i == 4 || i == 5) ? 1.0 : 0.0;
  float x0 = -1.0 + float(gl_ViewIndex);
  gl_Position = vec4(x0 + cx, -1.0 + 2.0 * cy, 0.0, 1.0);
  vColor = vec4(0.0, 0.0, 0.25 + 0.5 * float(gl_ViewIndex), 1.0);
}
