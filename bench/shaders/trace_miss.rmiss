#version 460
// The trace benchmark's miss shader (bench/shaders/trace_paths.rgen): t < 0.
#extension GL_EXT_ray_tracing : require

#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;

void main() { payload.t = -1.0; }
