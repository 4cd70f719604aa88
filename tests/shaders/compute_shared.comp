#version 460
// Workgroup memory and barriers: each workgroup reverses its slice through shared memory, then computes a
// tree reduction of it (log2(64) barrier-separated steps), and counts its invocations with a workgroup atomic.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) buffer Data { uint v[]; } data;
layout(set = 0, binding = 1, std430) buffer Sums { uint s[]; } sums;
shared uint tile[64];
shared uint red[64];
shared uint arrived;

void main() {
  uint l = gl_LocalInvocationID.x;
  uint g = gl_GlobalInvocationID.x;
  if (l == 0u) arrived = 0u;
  barrier();
  tile[l] = data.v[g];
  red[l] = data.v[g];
  atomicAdd(arrived, 1u);
  barrier();
  data.v[g] = tile[63u - l];
  for (uint stride = 32u; stride > 0u; stride >>= 1u) {
    if (l < stride) red[l] += red[l + stride];
    barrier();
  }
  if (l == 0u) {
    sums.s[2u * gl_WorkGroupID.x] = red[0];
    sums.s[2u * gl_WorkGroupID.x + 1u] = arrived;
  }
}
