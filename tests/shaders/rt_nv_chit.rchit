#version 460
#extension GL_NV_ray_tracing : require
// rt_chit.rchit in the GL_NV_ray_tracing form (tests/spirv/ray_tracing_test.cpp traces the scene with both).
// Closest hit of both geometries: built-ins into the payload, a callable, and (for the sphere) a secondary ray
// back along -z, traced from inside the closest-hit shader (recursion depth 2).
struct Payload { vec4 a; vec4 b; vec4 c; uvec4 d; vec4 e; };
layout(location = 0) rayPayloadInNV Payload payload;
layout(location = 1) rayPayloadNV float shade;
layout(location = 0) callableDataNV uint data;
layout(binding = 0, set = 0) uniform accelerationStructureNV tlas;
layout(shaderRecordNV, std430) buffer Record { vec4 tint; };
hitAttributeNV vec2 attr;
void main() {
  payload.a = vec4(attr, gl_HitTNV, gl_RayTminNV);
  payload.b = vec4(gl_ObjectRayOriginNV, float(gl_PrimitiveID));
  payload.c = vec4(gl_ObjectToWorldNV[3], tint.w);
  payload.d = uvec4(gl_InstanceCustomIndexNV, gl_InstanceID, 0u, gl_HitKindNV);  // NV has no geometry index
  data = uint(gl_PrimitiveID) + 10u;
  executeCallableNV(0, 0);
  shade = -1.0;
  if (gl_HitKindNV == 5u) {
    vec3 hit = gl_WorldRayOriginNV + gl_WorldRayDirectionNV * gl_HitTNV;
    traceNV(tlas, gl_RayFlagsOpaqueNV, 0xff, 0, 1, 1, hit, 0.01, vec3(0, 0, -1), 100.0, 1);
  }
  payload.e = vec4(float(data), shade, gl_WorldToObjectNV[3].z, attr.x);
}
