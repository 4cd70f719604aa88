#version 450
// Position from an attribute; the color encodes gl_InstanceIndex and gl_VertexIndex (in 1/255 steps), so indirect
// draws show which record (firstVertex, firstIndex, vertexOffset) and instance drew each triangle (flat: the provoking
// vertex's index).
layout(location = 0) in vec2 inPos;
layout(location = 0) out vec4 vColor;
void main() {
  gl_Position = vec4(inPos, 0.0, 1.0);
  vColor = vec4(float(gl_InstanceIndex) / 255.0, float(gl_VertexIndex) / 255.0, 0.0, 1.0);
}
