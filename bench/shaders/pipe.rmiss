// The miss shader of the pipeline creation benchmark (bench/pipeline_bench.cpp): a sky gradient.
#version 460
#extension GL_EXT_ray_tracing : require

layout(constant_id = 0) const uint kVariant = 0;
layout(location = 0) rayPayloadInEXT vec4 payload;

void main() {
  float t = 0.5 * (gl_WorldRayDirectionEXT.y + 1.0);
  payload = vec4(mix(vec3(1.0), vec3(0.5, 0.7, 1.0) * (1.0 + 0.01 * float(kVariant)), t), 1.0);
}
