#version 450
// watchdog_spin.comp with a workgroup barrier (vkrt runs the workgroup's invocations as fibers): invocation
// `spinner` loops after the barrier, forever.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { uint data[]; };
layout(push_constant) uniform PC { uint spinner; };
shared uint staged[64];
void main() {
  uint i = gl_GlobalInvocationID.x;
  staged[gl_LocalInvocationID.x] = i + 1u;
  barrier();
  if (i == spinner) {
    for (uint n = 0u; data[0] != 0xffffffffu; ++n) data[1u + i] = n;
  }
  data[1u + i] = staged[gl_LocalInvocationID.x];
}
