#version 450
// Per-vertex position, per-instance offset and color (binding 1, input rate INSTANCE).
layout(location = 0) in vec2 inPos;
layout(location = 2) in vec2 inOffset;
layout(location = 3) in vec4 inColor;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos + inOffset, 0.0, 1.0);
  vColor = inColor;
}
