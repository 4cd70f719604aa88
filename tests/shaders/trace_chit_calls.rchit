#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// A closest-hit shader that calls: the callable of record 0 with gl_PrimitiveID as data (its answer goes to
// extra.z), and, when its record says so, a second ray onward from the hit point (the tag of what that ray meets
// goes to extra.w, 1000 x its gl_HitTEXT to extra.y).
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload onward;
layout(location = 0) callableDataEXT uint data;
layout(binding = 0, set = 0) uniform accelerationStructureEXT tlas;
layout(shaderRecordEXT, std430) buffer Record { uint tag; uint recurse; };
hitAttributeEXT vec2 attr;
void main() {
  payload.hit = vec4(gl_HitTEXT, attr.x, attr.y, float(gl_HitKindEXT));
  payload.ids = uvec4(gl_InstanceCustomIndexEXT, gl_InstanceID, gl_PrimitiveID, gl_GeometryIndexEXT);
  payload.extra.x = tag;
  data = uint(gl_PrimitiveID);
  executeCallableEXT(0, 0);
  payload.extra.z = data;
  if (recurse != 0u) {
    onward.hit = vec4(-1.0);
    onward.extra = uvec4(0u);
    vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    traceRayEXT(tlas, gl_RayFlagsNoneEXT, 0xff, 0, 1, 0, p, 0.01, gl_WorldRayDirectionEXT, 100.0, 1);
    payload.extra.w = onward.extra.x;
    payload.extra.y = uint(onward.hit.x * 1000.0 + 0.5);
  }
}
