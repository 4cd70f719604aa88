#version 460
#extension GL_EXT_ray_query : require
// Ray queries on hundreds of top-level structures in one dispatch (tests/e2e/ray_query_test.cpp): invocation i
// queries the structure at addresses[(i * 7919) % count] with one ray along +z from (0.25, 0.25, -10) and writes the
// committed instance's custom index (0xFFFFFFFF when nothing is committed).
layout(local_size_x = 64) in;
layout(push_constant) uniform Params { uint count; } pc;
layout(set = 0, binding = 0, std430) readonly buffer Addresses { uvec2 addresses[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint result[]; };
void main() {
  const uint i = gl_GlobalInvocationID.x;
  rayQueryEXT q;
  rayQueryInitializeEXT(q, accelerationStructureEXT(addresses[(i * 7919u) % pc.count]), gl_RayFlagsOpaqueEXT, 0xffu,
                        vec3(0.25, 0.25, -10.0), 0.0, vec3(0.0, 0.0, 1.0), 100.0);
  while (rayQueryProceedEXT(q)) {
  }
  result[i] = rayQueryGetIntersectionTypeEXT(q, true) == gl_RayQueryCommittedIntersectionTriangleEXT
                  ? rayQueryGetIntersectionInstanceCustomIndexEXT(q, true)
                  : 0xFFFFFFFFu;
}
