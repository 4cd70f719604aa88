#version 460
// The basic subgroup operations vkrt advertises (VkPhysicalDeviceSubgroupProperties: size 1, compute):
// every invocation is its own subgroup, elected, with subgroup barriers that synchronize nothing else.
#extension GL_KHR_shader_subgroup_basic : require
layout(local_size_x = 4, local_size_y = 2) in;
layout(set = 0, binding = 0) buffer Out { uvec4 values[]; };
void main() {
  subgroupBarrier();
  subgroupMemoryBarrier();
  uint i = gl_LocalInvocationIndex + gl_WorkGroupID.x * 8u;
  values[i] = uvec4(subgroupElect() ? 1u : 0u, gl_SubgroupSize, gl_SubgroupInvocationID,
                    gl_NumSubgroups * 100u + gl_SubgroupID);
}
