#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// trace_miss.rmiss without a shader record (for SBT records that are only a handle): tag 77, gl_RayTmaxEXT, flags.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
  payload.hit = vec4(-2.0, 77.0, gl_RayTmaxEXT, float(gl_IncomingRayFlagsEXT));
  payload.extra.x = 77u;
}
