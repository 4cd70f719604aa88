#version 460
// Uses a subgroup operation (OpGroupNonUniformElect), which the compiler does not support yet: pipeline creation
// must fail with a message naming the instruction.
#extension GL_KHR_shader_subgroup_basic : require
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Out { uint elected[]; };
void main() { elected[gl_GlobalInvocationID.x] = subgroupElect() ? 1u : 0u; }
