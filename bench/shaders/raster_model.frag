#version 450
// The raster benchmark's model pass: the base colour texture (implicit LOD, trilinear) under one directional light.
layout(set = 0, binding = 0) uniform sampler2D baseColor;
layout(location = 0) in vec3 inNormal;
layout(location = 1) in vec2 inUv;
layout(location = 0) out vec4 outColor;
void main() {
  const vec3 light = normalize(vec3(0.4, 0.7, 0.6));
  const float diffuse = max(dot(normalize(inNormal), light), 0.0);
  const vec4 albedo = texture(baseColor, inUv);
  outColor = vec4(albedo.rgb * (0.25 + 0.75 * diffuse), 1.0);
}
