#version 460
#extension GL_EXT_ray_tracing : require
// stack_chit_trace_attr.rchit without hit attributes: the same call, the same payloads.
layout(location = 0) rayPayloadInEXT vec4 incoming;
layout(location = 1) rayPayloadEXT vec4 outgoing;
void main() {
  traceRayEXT(accelerationStructureEXT(floatBitsToUint(incoming.xy)), gl_RayFlagsOpaqueEXT, 0xff, 0, 0, 0,
              vec3(0), 0.0, vec3(0, 0, 1), 100.0, 1);
  incoming = outgoing + vec4(gl_HitTEXT);
}
