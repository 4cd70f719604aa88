#version 450
// watchdog_fault.comp after a workgroup barrier (vkrt runs the workgroup's invocations as fibers).
#extension GL_EXT_buffer_reference : require
layout(local_size_x = 64) in;
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint data[]; };
layout(push_constant) uniform PC {
  Words good;
  Words wild;
  uint faulter;
};
shared uint staged[64];
void main() {
  uint i = gl_GlobalInvocationID.x;
  staged[gl_LocalInvocationID.x] = i + 1u;
  barrier();
  if (i == faulter) {
    wild.data[0] = i;
    return;
  }
  good.data[i] = staged[gl_LocalInvocationID.x];
}
