#version 460
// Workgroup barriers and workgroup memory on the SPMD path (tests/spirv/spmd_test.cpp): each workgroup (any shape up
// to 256 invocations, specialization constants 0 and 1) stages its inputs in shared memory, counts its invocations and
// takes the maximum with workgroup atomics, exchanges neighbours for `rounds` rounds (a uniform loop with two barriers
// a round, the neighbours at other lanes, other batches, and around the end), runs a branch with barriers where the
// push constant `flag` says (uniform), and sums its values by a tree reduction (a varying condition inside a loop
// with a barrier after it); then stores past the end of `a` (which would land in `b` were they not dropped) and reads
// past it (zeros). Every invocation writes five words.
layout(local_size_x_id = 0, local_size_y_id = 1) in;
layout(set = 0, binding = 0, std430) readonly buffer In { uint v[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint o[]; };
layout(push_constant) uniform P { uint rounds; uint flag; } pc;
shared uint a[256];
shared uint b[256];
shared uint counter;
shared uint maxv;

void main() {
  uint n = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  uint l = gl_LocalInvocationIndex;
  uint g = gl_WorkGroupID.x * n + l;
  if (l == 0u) {
    counter = 0u;
    maxv = 0u;
  }
  a[l] = v[g];
  barrier();
  atomicAdd(counter, 1u);
  atomicMax(maxv, a[l] ^ 0x5a5a5a5au);
  for (uint r = 0u; r < pc.rounds; ++r) {
    uint left = a[(l + n - 1u) % n], right = a[(l + 1u) % n];
    barrier();
    a[l] = left * 3u + right + r;
    barrier();
  }
  if (pc.flag != 0u) {
    b[l] = a[n - 1u - l];
    barrier();
    a[l] = b[l] + 1u;
    barrier();
  }
  b[l] = a[l];
  barrier();
  for (uint s = 128u; s > 0u; s >>= 1u) {
    if (l < s && l + s < n) b[l] += b[l + s];
    barrier();
  }
  a[256u + l % 4u] = 0xbadu;
  barrier();
  o[5u * g] = a[l];
  o[5u * g + 1u] = b[0];
  o[5u * g + 2u] = counter;
  o[5u * g + 3u] = maxv;
  o[5u * g + 4u] = a[(l & 1u) == 0u ? (l * 7u) % n : 256u + l * 3u];
}
