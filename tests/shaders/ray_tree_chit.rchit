#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// The ray tree test's closest-hit shader (tests/e2e/ray_tree_test.cpp): records the hit as trace_chit.rchit does,
// then traces two secondary rays from (hit x, hit y, 4.5): along +x (into the scene's box) and along -x (a miss),
// each with a payload of known bytes.
#include "trace_payload.glsl"
layout(binding = 0, set = 0) uniform accelerationStructureEXT tlas;
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload secondary;
layout(shaderRecordEXT, std430) buffer Record { uint tag; };
hitAttributeEXT vec2 attr;
void main() {
  payload.hit = vec4(gl_HitTEXT, attr.x, attr.y, float(gl_HitKindEXT));
  payload.ids = uvec4(gl_InstanceCustomIndexEXT, gl_InstanceID, gl_PrimitiveID, gl_GeometryIndexEXT);
  payload.extra.x = tag;
  vec3 p = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  vec3 origin = vec3(p.xy, 4.5);
  for (int k = 0; k < 2; ++k) {
    secondary.hit = vec4(0.0);
    secondary.ids = uvec4(7u);
    secondary.extra = uvec4(uint(k));
    traceRayEXT(tlas, gl_RayFlagsNoneEXT, 0xff, 0, 1, 0, origin, 0.0, vec3(k == 0 ? 1.0 : -1.0, 0.0, 0.0), 100.0, 1);
  }
}
