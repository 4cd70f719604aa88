#version 460
#extension GL_EXT_ray_tracing : require
// The miss shader of the secondary rays (location 1: a single float).
layout(location = 1) rayPayloadInEXT float shade;
void main() { shade = 0.25 + gl_WorldRayDirectionEXT.z; }
