#version 460
// Data-dependent indices (a gather that may go anywhere), vec4 accesses that straddle the end of their buffer,
// and a signed index that goes negative: out-of-range parts read zero and are not written. Used by the
// per-workgroup entry tests.
layout(local_size_x = 32, local_size_y = 2) in;
layout(set = 0, binding = 0, std430) readonly buffer Src { float src[]; };
layout(set = 0, binding = 1, std430) readonly buffer Index { uint index[]; };
layout(set = 0, binding = 2, std430) writeonly buffer Gathered { float gathered[]; };
layout(set = 0, binding = 3, std430) buffer Vectors { vec4 v[]; };
layout(push_constant) uniform Push { int shift; } pc;
void main() {
  uint i = gl_GlobalInvocationID.y * 64u + gl_GlobalInvocationID.x;
  gathered[i] = src[index[i]] + src[int(i) - pc.shift];
  v[i] = v[i] * 2.0 + vec4(1.0, 2.0, 3.0, 4.0);
}
