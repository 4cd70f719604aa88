#version 460
#extension GL_EXT_ray_tracing : require
// Closest hit of both geometries: built-ins into the payload, a callable, and (for the sphere) a secondary ray
// back along -z, traced from inside the closest-hit shader (recursion depth 2).
struct Payload { vec4 a; vec4 b; vec4 c; uvec4 d; vec4 e; };
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT float shade;
layout(location = 0) callableDataEXT uint data;
layout(binding = 0, set = 0) uniform accelerationStructureEXT tlas;
layout(shaderRecordEXT, std430) buffer Record { vec4 tint; };
hitAttributeEXT vec2 attr;
void main() {
  payload.a = vec4(attr, gl_HitTEXT, gl_RayTminEXT);
  payload.b = vec4(gl_ObjectRayOriginEXT, float(gl_PrimitiveID));
  payload.c = vec4(gl_ObjectToWorldEXT[3], tint.w);
  payload.d = uvec4(gl_InstanceCustomIndexEXT, gl_InstanceID, gl_GeometryIndexEXT, gl_HitKindEXT);
  data = uint(gl_PrimitiveID) + 10u;
  executeCallableEXT(0, 0);
  shade = -1.0;
  if (gl_HitKindEXT == 5u) {
    vec3 hit = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
    traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xff, 0, 1, 1, hit, 0.01, vec3(0, 0, -1), 100.0, 1);
  }
  payload.e = vec4(float(data), shade, gl_WorldToObjectEXT[3].z, attr.x);
}
