#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_ray_cull_mask : require
#extension GL_GOOGLE_include_directive : require
// The miss shader of trace_miss.rmiss that also records gl_CullMaskEXT (SPV_KHR_ray_cull_mask) in extra.z.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
layout(shaderRecordEXT, std430) buffer Record { uint tag; };
void main() {
  payload.hit = vec4(-2.0, float(tag), gl_RayTmaxEXT, float(gl_IncomingRayFlagsEXT));
  payload.extra.x = tag;
  payload.extra.z = gl_CullMaskEXT;
}
