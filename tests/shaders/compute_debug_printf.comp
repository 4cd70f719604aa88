#version 450
// debugPrintfEXT: glslc emits it in the NonSemantic.DebugPrintf instruction set (SPV_KHR_non_semantic_info); the
// results do not depend on it. Invocation i writes 7i + 1.
#extension GL_EXT_debug_printf : require
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  debugPrintfEXT("invocation %u writes %u", i, i * 7u + 1u);
  o[i] = i * 7u + 1u;
}
