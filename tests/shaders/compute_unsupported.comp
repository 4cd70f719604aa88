#version 460
// Uses a subgroup ballot (OpGroupNonUniformBallot), which the compiler does not support (vkrt advertises only the
// basic subgroup operations): pipeline creation must fail with a message naming the instruction.
#extension GL_KHR_shader_subgroup_ballot : require
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Out { uvec4 ballots[]; };
void main() { ballots[gl_GlobalInvocationID.x] = subgroupBallot(true); }
