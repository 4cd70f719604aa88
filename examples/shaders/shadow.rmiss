#version 460
#extension GL_EXT_ray_tracing : require
// The shadow ray met nothing between the point and the light.
layout(location = 1) rayPayloadInEXT float lit;
void main() { lit = 1.0; }
