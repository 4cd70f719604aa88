#version 460
#extension GL_NV_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// trace_miss.rmiss in the GL_NV_ray_tracing form.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInNV Payload payload;
layout(shaderRecordNV, std430) buffer Record { uint tag; };
void main() {
  payload.hit = vec4(-2.0, float(tag), gl_RayTmaxNV, float(gl_IncomingRayFlagsNV));
  payload.extra.x = tag;
}
