#version 450
// tests/e2e/watchdog_test.cpp: invocation `spinner` loops until data[0] is 0xffffffff, which never happens (the
// watchdog ends it); every other invocation writes its index + 1 to data[1 + index].
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Data { uint data[]; };
layout(push_constant) uniform PC { uint spinner; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i == spinner) {
    // (The store keeps the loop: an optimizer may drop a loop that has no effect.)
    for (uint n = 0u; data[0] != 0xffffffffu; ++n) data[1u + i] = n;
  }
  data[1u + i] = i + 1u;
}
