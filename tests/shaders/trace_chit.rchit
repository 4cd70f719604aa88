#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// Records the hit's built-ins and its shader record's tag.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
layout(shaderRecordEXT, std430) buffer Record { uint tag; };
hitAttributeEXT vec2 attr;
void main() {
  payload.hit = vec4(gl_HitTEXT, attr.x, attr.y, float(gl_HitKindEXT));
  payload.ids = uvec4(gl_InstanceCustomIndexEXT, gl_InstanceID, gl_PrimitiveID, gl_GeometryIndexEXT);
  payload.extra.x = tag;
}
