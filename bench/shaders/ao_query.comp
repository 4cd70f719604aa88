#version 460
// Ambient occlusion rays from a compute shader (bench/bench.cpp, BM_AmbientOcclusion_vkrt): one invocation per
// point, `raysPerPoint` rays from it with ray queries that stop at the first opaque hit. The directions come from
// the integer hash that aoDirection() in bench.cpp reimplements, with only exact float operations, so the C++ side
// (raw Embree) traces bit-identical rays. Writes (occluded count, mask of occluded rays) per point.
#extension GL_EXT_ray_query : require

layout(local_size_x = 64) in;

layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1, std430) readonly buffer Points { vec4 origins[]; };
layout(set = 0, binding = 2, std430) writeonly buffer Results { uvec2 results[]; };

layout(push_constant) uniform Params {
  uint count;
  uint raysPerPoint;  // at most 32 (the mask)
  float tMin;
  float tMax;
};

#include "hash.glsl"

// x, y in [-1, 1), z in (0, 1]: 16-bit integers scaled by powers of two, exact in float.
vec3 aoDirection(uint point, uint k) {
  uint h1 = hash(point * raysPerPoint + k);
  uint h2 = hash(h1);
  uint h3 = hash(h2);
  return vec3(float(int(h1 >> 16) - 32768) * (1.0 / 32768.0), float(int(h2 >> 16) - 32768) * (1.0 / 32768.0),
              float((h3 >> 16) + 1u) * (1.0 / 65536.0));
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec3 o = origins[i].xyz;
  uint occluded = 0, mask = 0;
  for (uint k = 0; k < raysPerPoint; ++k) {
    rayQueryEXT q;
    rayQueryInitializeEXT(q, tlas, gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsOpaqueEXT, 0xff, o, tMin,
                          aoDirection(i, k), tMax);
    while (rayQueryProceedEXT(q)) {
    }
    if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionNoneEXT) {
      ++occluded;
      mask |= 1u << k;
    }
  }
  results[i] = uvec2(occluded, mask);
}
