#version 450
// PhysicalStorageBuffer64 pointers (GL_EXT_buffer_reference): loads, stores and access chains through device
// addresses taken from push constants and from memory, and pointer <-> integer conversions.
#extension GL_EXT_buffer_reference : require
#extension GL_ARB_gpu_shader_int64 : require
layout(local_size_x = 16) in;
layout(buffer_reference) buffer Node;
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Node {
  vec4 v;
  Node next;
  uint tag;
};
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint data[]; };
layout(push_constant) uniform PC {
  Node head;
  Words outWords;
  uint count;
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  Node n = head;
  uint steps = i % 5u;
  uint sum = 0u;
  for (uint s = 0u; s < steps; ++s) {
    sum += n.tag;
    n = n.next;
  }
  outWords.data[2u * i] = sum + uint(n.v.x);
  // The i-th node computed from the head's address (OpConvertPtrToU / OpConvertUToPtr): 32-byte nodes.
  Node m = Node(uint64_t(head) + uint64_t(32u * (i % 5u)));
  outWords.data[2u * i + 1u] = m.tag * 1000u + uint(m.v.y);
  if (i < 5u) m.v.w = float(i * 3u);
}
