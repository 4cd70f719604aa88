// Push descriptors of images (tests/e2e/push_descriptor_test.cpp): a sampled image with a sampler binding whose
// sampler is immutable, a combined image sampler with an immutable sampler, and a storage image, all of the push set
// 0. Texel p of the 4 x 4 output is packUnorm4x8(tex at p) ^ (packUnorm4x8(combined at p) << 1).
#version 450
layout(local_size_x = 4, local_size_y = 4) in;
layout(set = 0, binding = 0) uniform texture2D tex;
layout(set = 0, binding = 1) uniform sampler smp;
layout(set = 0, binding = 2) uniform sampler2D combined;
layout(set = 0, binding = 3, r32ui) uniform writeonly uimage2D outImg;

void main() {
  ivec2 p = ivec2(gl_LocalInvocationID.xy);
  vec2 uv = (vec2(p) + 0.5) / 4.0;
  uint a = packUnorm4x8(textureLod(sampler2D(tex, smp), uv, 0.0));
  uint b = packUnorm4x8(textureLod(combined, uv, 0.0));
  imageStore(outImg, p, uvec4(a ^ (b << 1)));
}
