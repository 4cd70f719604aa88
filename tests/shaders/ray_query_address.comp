#version 460
#extension GL_EXT_ray_query : require
// A ray query on the acceleration structure at an address from the push constants (tests/e2e/ray_query_test.cpp):
// one ray along +z from (0.25, 0.25, -10); writes the committed type and t and the number of candidates.
layout(local_size_x = 1) in;
layout(push_constant) uniform Params { uvec2 address; } pc;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uvec4 result; };
void main() {
  rayQueryEXT q;
  rayQueryInitializeEXT(q, accelerationStructureEXT(pc.address), 0u, 0xffu, vec3(0.25, 0.25, -10.0), 0.0,
                        vec3(0.0, 0.0, 1.0), 100.0);
  uint candidates = 0;
  while (rayQueryProceedEXT(q)) {
    ++candidates;
    rayQueryConfirmIntersectionEXT(q);
  }
  result = uvec4(rayQueryGetIntersectionTypeEXT(q, true), floatBitsToUint(rayQueryGetIntersectionTEXT(q, true)),
                 candidates, 7u);
}
