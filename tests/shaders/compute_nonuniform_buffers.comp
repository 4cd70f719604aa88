#version 450
// Descriptor arrays indexed per invocation (GL_EXT_nonuniform_qualifier): a runtime-sized array of storage
// buffers, read, written, counted with atomics and measured with length(), and a uniform-buffer array; each
// invocation of a workgroup picks another element.
#extension GL_EXT_nonuniform_qualifier : require
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) buffer Data { uint head; uint v[]; } data[];
layout(set = 0, binding = 1, std140) uniform Params { uvec4 p; } params[3];
layout(set = 0, binding = 2, std430) writeonly buffer Out { uint o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint b = (i * 7u) % 5u;
  uint u = (i + i / 3u) % 3u;
  uint x = data[nonuniformEXT(b)].v[i];
  uvec4 q = params[nonuniformEXT(u)].p;
  data[nonuniformEXT(b)].v[i] = x * 3u + q.x;
  atomicAdd(data[nonuniformEXT(b)].head, 1u);
  o[i * 4u + 0u] = x;
  o[i * 4u + 1u] = q.y ^ q.z;
  o[i * 4u + 2u] = uint(data[nonuniformEXT(b)].v.length());
  o[i * 4u + 3u] = params[nonuniformEXT(i % 3u)].p.w + b * 1000u;
}
