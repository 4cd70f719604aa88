#version 460
#extension GL_NV_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// trace_chit.rchit in the GL_NV_ray_tracing form. GL_NV_ray_tracing has no geometry index: 0 is written, which is
// what the KHR shader writes for the one-geometry structures the NV test traces.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInNV Payload payload;
layout(shaderRecordNV, std430) buffer Record { uint tag; };
hitAttributeNV vec2 attr;
void main() {
  payload.hit = vec4(gl_HitTNV, attr.x, attr.y, float(gl_HitKindNV));
  payload.ids = uvec4(gl_InstanceCustomIndexNV, gl_InstanceID, gl_PrimitiveID, 0u);
  payload.extra.x = tag;
}
