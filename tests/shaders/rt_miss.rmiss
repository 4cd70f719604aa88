#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { vec4 a; vec4 b; vec4 c; uvec4 d; vec4 e; };
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
  payload.a = vec4(gl_WorldRayDirectionEXT, gl_RayTminEXT);
  payload.b = vec4(gl_WorldRayOriginEXT, gl_RayTmaxEXT);
  payload.d = uvec4(1000u + gl_IncomingRayFlagsEXT, gl_LaunchIDEXT.x, gl_LaunchSizeEXT.y, 7u);
}
