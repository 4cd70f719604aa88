#version 460
// Writes every invocation's built-ins, and a private-variable running value, at its linear global index;
// used by the per-workgroup entry tests (a 3-D workgroup, so that every loop level of vkrt_group runs).
layout(local_size_x = 4, local_size_y = 3, local_size_z = 2) in;
layout(set = 0, binding = 0) buffer Out { uvec4 v[]; } outBuf;
layout(push_constant) uniform Push { uint groupsX; uint groupsY; } pc;
uint counter = 7u;  // Private: starts at 7 in every invocation
void main() {
  counter += gl_LocalInvocationIndex;
  uvec3 g = gl_GlobalInvocationID;
  uint width = pc.groupsX * gl_WorkGroupSize.x, height = pc.groupsY * gl_WorkGroupSize.y;
  uint linear = (g.z * height + g.y) * width + g.x;
  uvec3 l = gl_LocalInvocationID;
  uvec3 w = gl_WorkGroupID;
  outBuf.v[linear * 3 + 0] = uvec4(g, gl_LocalInvocationIndex);
  outBuf.v[linear * 3 + 1] = uvec4(l, counter);
  outBuf.v[linear * 3 + 2] = uvec4(w, gl_NumWorkGroups.x);
}
