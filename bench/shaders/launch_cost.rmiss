#version 460
// The launch benchmark's miss shader (bench/launchbench.cpp): counts misses (none are expected).
#extension GL_EXT_ray_tracing : require

layout(location = 0) rayPayloadInEXT uint dummy;
layout(set = 0, binding = 0, std430) buffer Result {
  uint hits;
  uint misses;
  uint customIndex[];
};

void main() { atomicAdd(misses, 1); }
