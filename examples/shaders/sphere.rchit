#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "scene.glsl"
#include "shade.glsl"
hitAttributeEXT vec3 normal;  // object space, from sphere.rint
void main() {
  vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  vec3 n = normalize((gl_ObjectToWorldEXT * vec4(normal, 0.0)).xyz);
  payload.color = shade(p, n, materials[gl_InstanceCustomIndexEXT]);
}
