#version 460
#extension GL_EXT_ray_tracing : require
layout(constant_id = 0) const uint kValue = 0u;
layout(location = 0) rayPayloadInEXT vec4 payload;
void main() { payload = vec4(float(kValue)); }
