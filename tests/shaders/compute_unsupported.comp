#version 460
// Uses a subgroup shuffle (OpGroupNonUniformShuffle), which the compiler does not support (vkrt advertises the
// basic, vote and ballot subgroup operations): pipeline creation must fail with a message naming the instruction.
#extension GL_KHR_shader_subgroup_shuffle : require
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Out { uint values[]; };
void main() { values[gl_GlobalInvocationID.x] = subgroupShuffle(gl_GlobalInvocationID.x, 0u); }
