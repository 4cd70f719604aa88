#version 450
// The raster benchmark's model pass: the model drawn once per instance on a grid, each copy turned about y.
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(push_constant) uniform Push {
  mat4 viewProj;
  float grid;  // copies per row
  float angle;
} pc;
layout(location = 0) out vec3 outNormal;
layout(location = 1) out vec2 outUv;
void main() {
  const float g = pc.grid;
  const float col = mod(float(gl_InstanceIndex), g), row = floor(float(gl_InstanceIndex) / g);
  const float a = pc.angle + 0.7 * float(gl_InstanceIndex);
  const mat3 turn = mat3(cos(a), 0.0, -sin(a), 0.0, 1.0, 0.0, sin(a), 0.0, cos(a));
  const vec3 centre = vec3((col - (g - 1.0) * 0.5) * 1.2, ((g - 1.0) * 0.5 - row) * 1.2, 0.0);
  gl_Position = pc.viewProj * vec4(turn * inPosition + centre, 1.0);
  outNormal = turn * inNormal;
  outUv = inUv;
}
