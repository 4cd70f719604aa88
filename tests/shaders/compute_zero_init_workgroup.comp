#version 450
// Workgroup variables with null initializers (VK_KHR_zero_initialize_workgroup_memory, core in Vulkan 1.3): read
// before anything writes them they are zero, in every workgroup, with barriers between the phases.
#extension GL_EXT_null_initializer : require
layout(local_size_x = 8) in;
shared uint counter = {};
shared uint slots[8] = {};
layout(set = 0, binding = 0) buffer Out { uint before[16]; uint after[16]; uint slotsSeen[16]; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  uint l = gl_LocalInvocationID.x;
  before[i] = counter + slots[(l + 1u) % 8u];
  barrier();
  atomicAdd(counter, l + 1u);
  slots[l] = i + 100u;
  barrier();
  after[i] = counter;
  slotsSeen[i] = slots[(l + 1u) % 8u];
}
