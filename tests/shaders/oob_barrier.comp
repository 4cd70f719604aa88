#version 460
// oob_write.g.comp's store past the buffer's end after a workgroup barrier (tests/spirv/shader_debug_test.cpp): a
// shader with barriers runs invocation by invocation (fibers), and its reports are calls, not vkrt_group's log.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) buffer Out { uint o[]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  barrier();
  o[i + 100u] = i;
}
