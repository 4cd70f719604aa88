#version 450
// 64-bit integer atomics (VK_KHR_shader_atomic_int64) on a storage buffer and on workgroup memory, with values
// past 32 bits: invocation i of each 64-invocation workgroup adds (i << 33) + 5, takes the minimum of its negation
// and the maximum, sets bit i, and races a compare-exchange for `cas`; the workgroup's shared sum and minimum are
// written by invocation 0.
#extension GL_EXT_shader_atomic_int64 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, std430) buffer B {
  uint64_t sum;
  int64_t minimum;
  uint64_t maximum;
  uint64_t bits;
  uint64_t cas;
  uint64_t sharedSum[2];
  int64_t sharedMin[2];
  uint64_t returned[128];
};
shared uint64_t groupSum;
shared int64_t groupMin;

void main() {
  uint i = gl_LocalInvocationIndex;
  if (i == 0u) {
    groupSum = 0ul;
    groupMin = 0l;
  }
  barrier();
  uint64_t big = (uint64_t(i) << 33) + 5ul;
  atomicAdd(sum, big);
  atomicMin(minimum, -int64_t(big));
  atomicMax(maximum, big);
  atomicOr(bits, 1ul << i);
  returned[gl_GlobalInvocationID.x] = atomicCompSwap(cas, 0ul, (uint64_t(gl_GlobalInvocationID.x) << 40) | 0xabcul);
  atomicAdd(groupSum, big);
  atomicMin(groupMin, -int64_t(big));
  barrier();
  if (i == 0u) {
    sharedSum[gl_WorkGroupID.x] = groupSum;
    sharedMin[gl_WorkGroupID.x] = groupMin;
  }
}
