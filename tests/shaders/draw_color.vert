#version 450
// Position (NDC) and color from vertex attributes; the color goes to the fragment shader at location 0.
layout(location = 0) in vec2 inPos;
layout(location = 1) in vec4 inColor;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos, 0.0, 1.0);
  vColor = inColor;
}
