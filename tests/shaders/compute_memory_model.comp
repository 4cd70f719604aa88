#version 460
// The Vulkan memory model (Vulkan13RequirementsTest.VulkanMemoryModel): a module with OpMemoryModel Vulkan, loads
// and stores with NonPrivatePointer / MakePointerAvailable / MakePointerVisible, atomics and barriers with
// explicit scopes (Device, QueueFamily, Workgroup) and semantics. 4 workgroups of 64 invocations: each invocation
// publishes a value in workgroup memory, the workgroup's barrier makes it visible, and its neighbour reads it; each
// adds to a device-scope counter, and the last invocation of each workgroup stores through a release/acquire pair.
#pragma use_vulkan_memory_model
#extension GL_KHR_memory_scope_semantics : require
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) coherent buffer Out {
  uint counter;
  uint flags[4];
  uint neighbour[256];
};
shared uint published[64];
void main() {
  uint l = gl_LocalInvocationID.x;
  uint g = gl_WorkGroupID.x;
  published[l] = g * 1000u + l * 3u;
  controlBarrier(gl_ScopeWorkgroup, gl_ScopeWorkgroup, gl_StorageSemanticsShared,
                 gl_SemanticsAcquireRelease | gl_SemanticsMakeAvailable | gl_SemanticsMakeVisible);
  neighbour[g * 64u + l] = published[(l + 1u) % 64u];
  atomicAdd(counter, 1u, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelaxed);
  atomicAdd(counter, 1u, gl_ScopeQueueFamily, gl_StorageSemanticsBuffer,
            gl_SemanticsAcquireRelease | gl_SemanticsMakeAvailable | gl_SemanticsMakeVisible);
  memoryBarrier(gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelease | gl_SemanticsMakeAvailable);
  if (l == 63u) {
    atomicStore(flags[g], atomicLoad(counter, gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsAcquire |
                                     gl_SemanticsMakeVisible) > 0u ? g + 1u : 0u,
                gl_ScopeDevice, gl_StorageSemanticsBuffer, gl_SemanticsRelease | gl_SemanticsMakeAvailable);
  }
}
