#version 460
#extension GL_EXT_ray_tracing : require
// A closest-hit shader that traces a ray and uses its 16-byte hit attributes after the call: they are kept on
// its stack across traceRayEXT (the acceleration structure comes from the incoming payload: no descriptor).
layout(location = 0) rayPayloadInEXT vec4 incoming;
layout(location = 1) rayPayloadEXT vec4 outgoing;
hitAttributeEXT vec4 attr;
void main() {
  traceRayEXT(accelerationStructureEXT(floatBitsToUint(incoming.xy)), gl_RayFlagsOpaqueEXT, 0xff, 0, 0, 0,
              vec3(0), 0.0, vec3(0, 0, 1), 100.0, 1);
  incoming = outgoing + attr;
}
