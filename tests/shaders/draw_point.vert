#version 450
// One-pixel white points at the attribute's position (point clipping, VK_KHR_maintenance2).
layout(location = 0) in vec2 inPos;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos, 0.0, 1.0);
  gl_PointSize = 1.0;
  vColor = vec4(1.0);
}
