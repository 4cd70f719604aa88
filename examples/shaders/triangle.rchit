#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "scene.glsl"
#include "shade.glsl"
void main() {
  Triangle t = triangles[gl_InstanceCustomIndexEXT + gl_PrimitiveID];
  vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  // The table holds object-space normals; instances are rotated and moved, never scaled unevenly.
  vec3 n = normalize((gl_ObjectToWorldEXT * vec4(t.normalMaterial.xyz, 0.0)).xyz);
  payload.color = shade(p, n, materials[uint(t.normalMaterial.w)]);
}
