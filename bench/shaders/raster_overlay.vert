#version 450
// The raster benchmark's blended pass: one screen-space quad per instance (a 4-vertex strip), in front of the model.
layout(location = 0) out vec4 outColor;
void main() {
  const vec2 corner = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1));
  const float i = float(gl_InstanceIndex);
  const vec2 origin = vec2(-0.9 + 0.22 * i, -0.8 + 0.1 * i);
  gl_Position = vec4(origin + corner * vec2(0.6, 0.9), 0.05, 1.0);
  outColor = vec4(0.5 + 0.5 * sin(i), 0.5 + 0.5 * sin(i + 2.1), 0.5 + 0.5 * sin(i + 4.2), 0.35);
}
