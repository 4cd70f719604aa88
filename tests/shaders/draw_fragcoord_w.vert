#version 450
// Perspective without varying inputs (DrawQuadShadingTest.FragCoordWWhereNothingVaries): w_c = 1 + (x + 1) / 2
// per vertex (NDC x), z_ndc = 0.25; the color is the same at every vertex of draw_color.vert's full-screen triangle.
layout(location = 0) in vec2 inPos;
layout(location = 1) in vec4 inColor;
layout(location = 0) out vec4 vColor;
void main() {
  const float w = 1.0 + 0.5 * (inPos.x + 1.0);
  gl_Position = vec4(inPos * w, 0.25 * w, w);
  vColor = inColor;
}
