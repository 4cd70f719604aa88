#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// An analytic sphere hit: the outward normal at the hit point.
#include "pt.glsl"
layout(location = 0) rayPayloadInEXT HitPayload hit;
void main() {
  Sphere s = spheres[gl_InstanceCustomIndexEXT + gl_PrimitiveID];
  vec3 p = gl_ObjectRayOriginEXT + gl_ObjectRayDirectionEXT * gl_HitTEXT;
  vec3 n = normalize(transpose(mat3(gl_WorldToObjectEXT)) * (p - s.centerRadius.xyz));
  hit.position = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  hit.t = gl_HitTEXT;
  hit.normal = n;
  hit.material = s.material;
  hit.geometricNormal = n;
  hit.albedo = materials[s.material].baseColor.rgb;
}
