#version 460
#extension GL_EXT_ray_tracing : require
// The shadow ray met nothing before the light.
layout(location = 1) rayPayloadInEXT uint visible;
void main() { visible = 1u; }
