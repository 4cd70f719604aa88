#version 460
#extension GL_NV_ray_tracing : require
// rt_miss.rmiss in the GL_NV_ray_tracing form (tests/spirv/ray_tracing_test.cpp traces the scene with both).
struct Payload { vec4 a; vec4 b; vec4 c; uvec4 d; vec4 e; };
layout(location = 0) rayPayloadInNV Payload payload;
void main() {
  payload.a = vec4(gl_WorldRayDirectionNV, gl_RayTminNV);
  payload.b = vec4(gl_WorldRayOriginNV, gl_RayTmaxNV);
  payload.d = uvec4(1000u + gl_IncomingRayFlagsNV, gl_LaunchIDNV.x, gl_LaunchSizeNV.y, 7u);
}
