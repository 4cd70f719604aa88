#version 450
// Texel buffer descriptor arrays (VK_EXT_descriptor_indexing): a runtime-sized array of uniform texel buffers
// indexed per invocation (nonuniformEXT) and by a push constant (dynamically uniform), and an array of r32ui
// storage texel buffers indexed per invocation for imageLoad, imageStore, imageAtomicAdd and imageSize.
#extension GL_EXT_nonuniform_qualifier : require
layout(local_size_x = 16) in;
layout(set = 0, binding = 0) uniform samplerBuffer tables[];
layout(set = 0, binding = 1, r32ui) uniform uimageBuffer bins[3];
layout(set = 0, binding = 2, std430) writeonly buffer Out { vec4 o[]; };
layout(push_constant) uniform Push { uint pick; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint t = (i * 5u + 1u) % 4u;
  uint s = i % 3u;
  float mine = texelFetch(tables[nonuniformEXT(t)], int(i)).x;
  float picked = texelFetch(tables[pick], int(i)).x;
  uint old = imageLoad(bins[nonuniformEXT(s)], int(i / 3u)).x;
  imageStore(bins[nonuniformEXT(s)], int(i / 3u), uvec4(old * 10u + i));
  imageAtomicAdd(bins[nonuniformEXT(s)], 7, 1u);
  o[i] = vec4(mine, picked, float(textureSize(tables[nonuniformEXT(t)])), float(imageSize(bins[nonuniformEXT(s)])));
}
