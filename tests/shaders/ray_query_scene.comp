#version 460
// Ray queries from a compute shader (tests/e2e/ray_query_test.cpp): one ray per invocation, read from `rays`; every
// candidate is handled as `mode` says, and the committed intersection's values (and a log of the candidates) are
// written to `results`.
#extension GL_EXT_ray_query : require

layout(local_size_x = 8) in;

layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;

struct RayIn {
  vec4 origin;     // xyz, w = tMin
  vec4 direction;  // xyz, w = tMax
  uint flags;
  uint cullMask;
  uint mode;  // 0: confirm triangles, generate boxes at the entry t; 1: ignore every candidate; 2: terminate at the
              // first candidate (after confirming or generating it)
  uint pad;
};
layout(set = 0, binding = 1, std430) readonly buffer Rays { RayIn rays[]; };

struct Result {
  vec4 hit;     // committed t, barycentrics, type
  uvec4 ids;    // custom index, instance id, primitive, geometry
  uvec4 more;   // SBT offset, front face, triangle candidates, box candidates
  vec4 objectOrigin;
  vec4 objectDirection;
  vec4 objectToWorld[4];  // columns (xyz)
  vec4 worldToObject[4];
  vec4 ray;        // tMin, flags, candidate t of the first triangle candidate, first box candidate opaque
  vec4 worldOrigin;
  vec4 worldDirection;
  uvec4 firstCandidate;  // custom index, instance id, primitive, geometry of the first candidate
};
layout(set = 0, binding = 2, std430) writeonly buffer Results { Result results[]; };

// Where a ray enters a box [-h, h]^3 around the origin (object space), or -1.
float boxEntry(vec3 o, vec3 d, float h, float tMin) {
  vec3 inv = 1.0 / d;
  vec3 t0 = (vec3(-h) - o) * inv, t1 = (vec3(h) - o) * inv;
  vec3 lo = min(t0, t1), hi = max(t0, t1);
  float enter = max(max(lo.x, lo.y), max(lo.z, tMin));
  float leave = min(min(hi.x, hi.y), hi.z);
  return enter <= leave ? enter : -1.0;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= rays.length()) return;
  RayIn r = rays[i];
  rayQueryEXT q;
  rayQueryInitializeEXT(q, tlas, r.flags, r.cullMask, r.origin.xyz, r.origin.w, r.direction.xyz, r.direction.w);
  uint triangles = 0, boxes = 0;
  bool first = true;
  Result res;
  res.ray = vec4(rayQueryGetRayTMinEXT(q), float(rayQueryGetRayFlagsEXT(q)), -1, -1);
  res.worldOrigin = vec4(rayQueryGetWorldRayOriginEXT(q), 0);
  res.worldDirection = vec4(rayQueryGetWorldRayDirectionEXT(q), 0);
  res.firstCandidate = uvec4(0xffffffffu);
  while (rayQueryProceedEXT(q)) {
    bool triangle = rayQueryGetIntersectionTypeEXT(q, false) == gl_RayQueryCandidateIntersectionTriangleEXT;
    if (first) {
      res.firstCandidate = uvec4(rayQueryGetIntersectionInstanceCustomIndexEXT(q, false),
                                 rayQueryGetIntersectionInstanceIdEXT(q, false),
                                 rayQueryGetIntersectionPrimitiveIndexEXT(q, false),
                                 rayQueryGetIntersectionGeometryIndexEXT(q, false));
      if (triangle) res.ray.z = rayQueryGetIntersectionTEXT(q, false);
      else res.ray.w = rayQueryGetIntersectionCandidateAABBOpaqueEXT(q) ? 1 : 0;
      first = false;
    }
    if (triangle) {
      ++triangles;
      if (r.mode != 1) rayQueryConfirmIntersectionEXT(q);
    } else {
      ++boxes;
      float t = boxEntry(rayQueryGetIntersectionObjectRayOriginEXT(q, false),
                         rayQueryGetIntersectionObjectRayDirectionEXT(q, false), 0.5, r.origin.w);
      if (r.mode != 1 && t >= 0) rayQueryGenerateIntersectionEXT(q, t);
    }
    if (r.mode == 2) rayQueryTerminateEXT(q);
  }
  uint type = rayQueryGetIntersectionTypeEXT(q, true);
  res.hit = vec4(rayQueryGetIntersectionTEXT(q, true), rayQueryGetIntersectionBarycentricsEXT(q, true), float(type));
  res.ids = uvec4(rayQueryGetIntersectionInstanceCustomIndexEXT(q, true), rayQueryGetIntersectionInstanceIdEXT(q, true),
                  rayQueryGetIntersectionPrimitiveIndexEXT(q, true), rayQueryGetIntersectionGeometryIndexEXT(q, true));
  res.more = uvec4(rayQueryGetIntersectionInstanceShaderBindingTableRecordOffsetEXT(q, true),
                   rayQueryGetIntersectionFrontFaceEXT(q, true) ? 1 : 0, triangles, boxes);
  res.objectOrigin = vec4(rayQueryGetIntersectionObjectRayOriginEXT(q, true), 0);
  res.objectDirection = vec4(rayQueryGetIntersectionObjectRayDirectionEXT(q, true), 0);
  mat4x3 o2w = rayQueryGetIntersectionObjectToWorldEXT(q, true), w2o = rayQueryGetIntersectionWorldToObjectEXT(q, true);
  for (int c = 0; c < 4; ++c) {
    res.objectToWorld[c] = vec4(o2w[c], 0);
    res.worldToObject[c] = vec4(w2o[c], 0);
  }
  results[i] = res;
}
