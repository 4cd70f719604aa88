// Push descriptors in a compute shader (tests/e2e/push_descriptor_test.cpp): set 0 is an allocated set (bound with
// vkCmdBindDescriptorSets), set 1 the pipeline layout's push descriptor set. Invocation i writes
// src[i] * mul + add + bias[i] to dst[i].
#version 450
layout(local_size_x = 16) in;

layout(set = 0, binding = 0, std430) readonly buffer Bias { uint bias[]; };
layout(set = 1, binding = 0) uniform Params { uint mul; uint add; } params;
layout(set = 1, binding = 1, std430) readonly buffer Src { uint v[]; } src;
layout(set = 1, binding = 2, std430) writeonly buffer Dst { uint v[]; } dst;

void main() {
  uint i = gl_GlobalInvocationID.x;
  dst.v[i] = src.v[i] * params.mul + params.add + bias[i];
}
