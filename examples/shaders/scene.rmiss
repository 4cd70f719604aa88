#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "scene.glsl"
layout(location = 0) rayPayloadInEXT RadiancePayload payload;
void main() { payload.color = vec3(0.02, 0.02, 0.03); }
