#version 450
// tests/e2e/watchdog_test.cpp: invocation `faulter` stores through the wild device address `wild` (where nothing
// is mapped); every other invocation writes its index + 1 through `good`.
#extension GL_EXT_buffer_reference : require
layout(local_size_x = 64) in;
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint data[]; };
layout(push_constant) uniform PC {
  Words good;
  Words wild;
  uint faulter;
};
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i == faulter) {
    wild.data[0] = i;
    return;
  }
  good.data[i] = i + 1u;
}
