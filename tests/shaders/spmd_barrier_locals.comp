#version 460
// A compute shader with a barrier and a per-invocation array of LEN words (specialization constant 0), indexed
// dynamically: small, its batches run SPMD on fibers; large (N lanes times its bytes past what a batch's fiber stack
// holds), it stays on the scalar path, one fiber per invocation (tests/spirv/spmd_test.cpp).
layout(local_size_x = 32) in;
layout(constant_id = 0) const uint LEN = 16u;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint o[]; };
shared uint s[32];
void main() {
  uint l = gl_LocalInvocationIndex;
  uint local[LEN];
  for (uint i = 0u; i < LEN; ++i) local[i] = l * i + gl_WorkGroupID.x;
  s[l] = local[(l * 7u) % LEN];
  barrier();
  o[gl_GlobalInvocationID.x] = s[31u - l] + local[LEN - 1u];
}
