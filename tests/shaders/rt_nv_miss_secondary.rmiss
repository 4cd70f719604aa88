#version 460
#extension GL_NV_ray_tracing : require
// rt_miss_secondary.rmiss in the GL_NV_ray_tracing form (tests/spirv/ray_tracing_test.cpp traces the scene with both).
// The miss shader of the secondary rays (location 1: a single float).
layout(location = 1) rayPayloadInNV float shade;
void main() { shade = 0.25 + gl_WorldRayDirectionNV.z; }
