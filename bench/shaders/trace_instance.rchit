#version 460
// The trace benchmark's closest-hit shader for --many-blas (bench/tracebench.cpp): records t and the instance hit
// (its structures hold one triangle each, so the instance says which triangle).
#extension GL_EXT_ray_tracing : require

#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;

void main() {
  payload.t = gl_HitTEXT;
  payload.primitive = gl_InstanceID;
}
