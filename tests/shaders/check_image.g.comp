#version 460
// Image and texel buffer accesses checked by VKRT_SHADER_CHECKS=image (tests/e2e/shader_debug_test.cpp), compiled
// with -g. Mode 0 writes the 4x4 image at the invocation's texel plus `shift` (line 16); mode 1 reads it at that
// texel through imageLoad (line 18), texelFetch (line 19) and an atomic (line 20), and reads and writes the 16-texel
// buffer at the invocation's index plus shift.x (lines 21-22).
layout(local_size_x = 4, local_size_y = 4) in;
layout(set = 0, binding = 0, r32ui) uniform uimage2D img;
layout(set = 0, binding = 1) uniform usampler2D tex;
layout(set = 0, binding = 2, r32ui) uniform uimageBuffer texels;
layout(set = 0, binding = 3, std430) buffer Out { uint o[]; };
layout(push_constant) uniform PC { ivec2 shift; uint mode; uint value; };
void main() {
  uint i = gl_LocalInvocationIndex;
  ivec2 q = ivec2(gl_LocalInvocationID.xy) + shift;
  if (mode == 0u) {
    imageStore(img, q, uvec4(value + i));
  } else {
    o[i] = imageLoad(img, q).x;
    o[16u + i] = texelFetch(tex, q, 0).x;
    o[32u + i] = imageAtomicAdd(img, q, 0u);
    o[48u + i] = imageLoad(texels, int(i) + shift.x).x;
    imageStore(texels, int(i) + shift.x, uvec4(i + 1u));
  }
}
