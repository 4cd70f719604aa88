#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// Records the miss: its shader record's tag, gl_RayTmaxEXT and gl_IncomingRayFlagsEXT.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
layout(shaderRecordEXT, std430) buffer Record { uint tag; };
void main() {
  payload.hit = vec4(-2.0, float(tag), gl_RayTmaxEXT, float(gl_IncomingRayFlagsEXT));
  payload.extra.x = tag;
}
