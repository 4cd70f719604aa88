#version 460
// y = a * x + y over n floats, through buffer device addresses (buffer_reference pointers in push constants).
#extension GL_EXT_buffer_reference : require
layout(local_size_x = 256) in;
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer Floats { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer RwFloats { float v[]; };
layout(push_constant) uniform Push { Floats x; RwFloats y; float a; uint n; } pc;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.n) pc.y.v[i] = pc.a * pc.x.v[i] + pc.y.v[i];
}
