#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_EXT_debug_printf : require
#extension GL_GOOGLE_include_directive : require
// trace_chit.rchit with a debugPrintfEXT line naming the hit (tests/e2e/shader_debug_test.cpp).
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
hitAttributeEXT vec2 attr;
void main() {
  debugPrintfEXT("closest hit: instance %d primitive %d t=%.2f", gl_InstanceCustomIndexEXT, gl_PrimitiveID, gl_HitTEXT);
  payload.hit = vec4(gl_HitTEXT, attr.x, attr.y, float(gl_HitKindEXT));
  payload.ids = uvec4(gl_InstanceCustomIndexEXT, gl_InstanceID, gl_PrimitiveID, gl_GeometryIndexEXT);
}
