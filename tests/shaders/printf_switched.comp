#version 460
// A debugPrintfEXT that a specialization constant switches (tests/spirv/shader_debug_test.cpp): off, the call goes with
// its branch and the SPMD path takes the shader; on, every invocation prints. Each of the 8 invocations writes 3i + 1.
#extension GL_EXT_debug_printf : require
layout(local_size_x = 8) in;
layout(constant_id = 0) const bool kPrint = false;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (kPrint) debugPrintfEXT("i=%u", i);
  o[i] = 3u * i + 1u;
}
