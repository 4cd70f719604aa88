// The payload of the tracing e2e tests (tests/e2e/trace_fixture.hpp reads it back as TracePayload).
struct Payload {
  vec4 hit;     // closest hit: gl_HitTEXT, hit attribute x, hit attribute y, gl_HitKindEXT; miss: -2, tag, tmax, flags
  uvec4 ids;    // closest hit: gl_InstanceCustomIndexEXT, gl_InstanceID, gl_PrimitiveID, gl_GeometryIndexEXT
  uvec4 extra;  // x: the shader record's tag, y: any-hit invocations, z: callable answer, w: recursion result
};
