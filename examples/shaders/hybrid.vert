#version 460
// hybrid: the scene's vertex shader. World-space position, normal and albedo per vertex; the camera's matrix in
// push constants.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 albedo;

layout(push_constant) uniform Frame {
  mat4 viewProjection;
  vec4 toLight;  // xyz: unit vector towards the (directional) light
} frame;

layout(location = 0) out vec3 worldPosition;
layout(location = 1) out vec3 worldNormal;
layout(location = 2) flat out vec3 surfaceAlbedo;

void main() {
  worldPosition = position;
  worldNormal = normal;
  surfaceAlbedo = albedo;
  gl_Position = frame.viewProjection * vec4(position, 1.0);
}
