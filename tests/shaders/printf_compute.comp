#version 460
// debugPrintfEXT in a compute shader (tests/e2e/shader_debug_test.cpp, tests/spirv/shader_debug_test.cpp): each
// of the 8 invocations of a workgroup prints one line with a 32-bit unsigned, signed and hexadecimal value, a vector
// and a 64-bit value, and writes i + 1.
#extension GL_EXT_debug_printf : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint o[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  debugPrintfEXT("i=%u neg=%d hex=%x v=%v3f big=%lu", i, -int(i), i * 16u + 15u, vec3(float(i), 0.5, -2.0),
                 uint64_t(i) << 40);
  o[i] = i + 1u;
}
