#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// The miss shader of the CTS's pipeline_no_null_shaders_flag.*: its record is {uint geomType; uint geomIndex;
// ivec4 retValue;} (std430: retValue at bytes 16..31 after the handle), and it reads retValue only.
#include "trace_payload.glsl"
layout(location = 0) rayPayloadInEXT Payload payload;
layout(shaderRecordEXT, std430) buffer Record {
  uint geomType;
  uint geomIndex;
  ivec4 retValue;
};
void main() {
  payload.hit = vec4(-2.0, 0.0, 0.0, 0.0);
  payload.extra = uvec4(retValue);
}
