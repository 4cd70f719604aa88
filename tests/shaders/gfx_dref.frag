#version 450
// Depth-comparison sampling in a fragment shader (tests/e2e/depth_compare_test.cpp) over a 32 x 32 target at
// uv = fragCoord / 32 with the reference dref = ((x + 0.5) * 3 + (y + 0.5) * 5) / 256, fract'd into [0, 1):
// R texture (OpImageSampleDrefImplicitLod), G textureProj (OpImageSampleProjDrefImplicitLod), B the four results of
// textureGather (OpImageDrefGather) as bits (1, 2, 4, 8) / 15, A textureOffset with ConstOffset (-1, 1).
layout(set = 0, binding = 0) uniform sampler2DShadow shadow;
layout(location = 0) out vec4 color;

void main() {
  vec2 uv = gl_FragCoord.xy / 32.0;
  float dref = fract((gl_FragCoord.x * 3.0 + gl_FragCoord.y * 5.0) / 256.0);
  float r = texture(shadow, vec3(uv, dref));
  float g = textureProj(shadow, vec4(uv * 4.0, dref * 4.0, 4.0));
  float b = dot(textureGather(shadow, uv, dref), vec4(1.0, 2.0, 4.0, 8.0)) / 15.0;
  float a = textureOffset(shadow, vec3(uv, dref), ivec2(-1, 1));
  color = vec4(r, g, b, a);
}
