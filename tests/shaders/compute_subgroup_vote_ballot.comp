#version 460
// Vote and ballot operations, broadcasts with a dynamic id and on 8/16/64-bit types (Vulkan13RequirementsTest):
// 4 invocations, 20 words each; the expectations are in vulkan13_requirements_test.cpp.
#extension GL_KHR_shader_subgroup_vote : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_EXT_shader_explicit_arithmetic_types : require
#extension GL_EXT_shader_subgroup_extended_types_int8 : require
#extension GL_EXT_shader_subgroup_extended_types_int16 : require
#extension GL_EXT_shader_subgroup_extended_types_int64 : require
#extension GL_EXT_shader_subgroup_extended_types_float16 : require
layout(local_size_x = 4) in;
layout(set = 0, binding = 0) buffer Out { uint v[]; };
layout(set = 0, binding = 1) buffer In { uint dynamicId; uint ballotIndex; };
void main() {
  uint i = gl_LocalInvocationIndex;
  uint o = i * 20u;
  uint id = dynamicId;  // read at run time: a dynamic (but dynamically uniform) id, 0
  v[o + 0] = subgroupAll(i < 2u) ? 1u : 0u;
  v[o + 1] = subgroupAny(i == 3u) ? 1u : 0u;
  v[o + 2] = subgroupAllEqual(i * 3u) ? 1u : 0u;
  v[o + 3] = subgroupBroadcast(i * 7u + 1u, id);
  v[o + 4] = subgroupBroadcastFirst(i + 5u);
  uvec4 ballot = subgroupBallot((i & 1u) == 1u);
  v[o + 5] = ballot.x;
  v[o + 6] = ballot.y | ballot.z | ballot.w;
  v[o + 7] = subgroupInverseBallot(uvec4(1u, 0u, 0u, 0u)) ? 1u : 0u;
  v[o + 8] = subgroupBallotBitExtract(uvec4(0u, 0u, 1u << i, 0u), 64u + i) ? 1u : 0u;
  v[o + 9] = subgroupBallotBitExtract(uvec4(0u, 0u, 1u << i, 0u), ballotIndex) ? 1u : 0u;
  v[o + 10] = subgroupBallotBitCount(uvec4(3u, 7u, 0u, 0u));
  v[o + 11] = subgroupBallotExclusiveBitCount(uvec4(1u, 0u, 0u, 0u));
  v[o + 12] = subgroupBallotInclusiveBitCount(uvec4(1u, 0u, 0u, 0u));
  v[o + 13] = subgroupBallotFindLSB(uvec4(1u, 0u, 0u, 0u)) + 10u;
  v[o + 14] = subgroupBallotFindMSB(uvec4(1u, 0u, 0u, 0u)) + 10u;
  v[o + 15] = uint(int(subgroupBroadcast(int8_t(-3 - int(i)), id)));
  v[o + 16] = uint(subgroupBroadcastFirst(uint16_t(60000u + i)));
  v[o + 17] = uint(subgroupBroadcast(uint64_t(i + 1u) << 40, id) >> 40);
  v[o + 18] = uint(float(subgroupBroadcast(float16_t(float(i) + 0.5), id)) * 2.0);
  v[o + 19] = subgroupAll(int16_t(i) < int16_t(2)) && subgroupAllEqual(uint64_t(i) << 33) ? 1u : 0u;
}
