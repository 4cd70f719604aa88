#version 460
#extension GL_EXT_ray_query : require
// hybrid: the rasterized scene's fragment shader. Lambert shading under a directional light, the shadow found by a
// ray query against the scene's top-level acceleration structure (VK_KHR_ray_query in a fragment shader), and grid
// lines on the floor whose width comes from screen-space derivatives (fwidth: the 2x2 quads).
layout(location = 0) in vec3 worldPosition;
layout(location = 1) in vec3 worldNormal;
layout(location = 2) flat in vec3 surfaceAlbedo;

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;

layout(push_constant) uniform Frame {
  mat4 viewProjection;
  vec4 toLight;
} frame;

layout(location = 0) out vec4 color;

const float kAmbient = 0.25;

void main() {
  vec3 n = normalize(worldNormal);
  vec3 l = frame.toLight.xyz;
  float diffuse = max(dot(n, l), 0.0);
  if (diffuse > 0.0) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, scene, gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT, 0xFF,
                          worldPosition + n * 1e-3, 1e-3, l, 1e4);
    while (rayQueryProceedEXT(q)) {
    }
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT) diffuse = 0.0;
  }
  vec3 albedo = surfaceAlbedo;
  if (n.y > 0.9 && worldPosition.y < 1e-3) {
    // Floor: lines one unit apart, one pixel wide whatever the distance.
    vec2 cell = abs(fract(worldPosition.xz) - 0.5) / fwidth(worldPosition.xz);
    float line = clamp(min(cell.x, cell.y), 0.0, 1.0);
    albedo *= mix(0.45, 1.0, line);
  }
  color = vec4(albedo * (kAmbient + (1.0 - kAmbient) * diffuse), 1.0);
}
