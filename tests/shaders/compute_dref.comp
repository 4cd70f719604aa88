#version 450
// Depth-comparison sampling and gathers (tests/e2e/depth_compare_test.cpp): textureLod and textureGrad on a
// sampler2DShadow (OpImageSampleDrefExplicitLod with Lod, with Grad), textureProjLod (OpImageSampleProjDrefExplicitLod),
// textureLodOffset (ConstOffset (1, -1)), textureGather with a reference (OpImageDrefGather) and of the same depth
// view through a sampler2D without compare (OpImageGather, component 0: the depths).
layout(local_size_x = 4) in;
layout(set = 0, binding = 0) uniform sampler2DShadow shadow;
layout(set = 0, binding = 1) uniform sampler2D plain;
layout(set = 0, binding = 2) readonly buffer In { vec4 q[]; };  // (u, v, dref, unused)
layout(set = 0, binding = 3) buffer Out { vec4 r[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 c = q[i];
  float lod = textureLod(shadow, c.xyz, 0.0);
  float proj = textureProjLod(shadow, vec4(c.xy * 2.0, c.z * 2.0, 2.0), 0.0);
  float grad = textureGrad(shadow, c.xyz, vec2(0.0), vec2(0.0));
  float offset = textureLodOffset(shadow, c.xyz, 0.0, ivec2(1, -1));
  r[3 * i + 0] = vec4(lod, proj, grad, offset);
  r[3 * i + 1] = textureGather(shadow, c.xy, c.z);
  r[3 * i + 2] = textureGather(plain, c.xy, 0);
}
