#version 460
// The trace benchmark's closest-hit shader: only the distance and the primitive (bench/shaders/trace_paths.rgen).
#extension GL_EXT_ray_tracing : require

#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;

void main() {
  payload.t = gl_HitTEXT;
  payload.primitive = gl_PrimitiveID;
}
