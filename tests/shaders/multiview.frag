#version 450
#extension GL_EXT_multiview : require
// Multiview: red for view 0, green for view 1 (the fragment stage's ViewIndex), blue from the vertex stage.
layout(location = 0) flat in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vec4(gl_ViewIndex == 0 ? 1.0 : 0.0, gl_ViewIndex == 1 ? 1.0 : 0.0, vColor.b, 1.0);
}
