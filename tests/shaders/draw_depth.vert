#version 450
// Position with depth (x, y, z in NDC) and a color; for the depth, stencil and depth bias tests.
layout(location = 0) in vec3 inPos;
layout(location = 1) in vec4 inColor;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos, 1.0);
  vColor = inColor;
}
