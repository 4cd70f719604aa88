#version 450
// Derivatives of a known function of the fragment coordinate (GraphicsShader.Derivatives), and quad operations.
#extension GL_KHR_shader_subgroup_quad : require
layout(location = 0) flat in int killLane;
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
layout(location = 2) out vec4 o2;
void main() {
  if (killLane == 1 && gl_FragCoord.x > 1.0 && gl_FragCoord.y > 1.0 && int(gl_FragCoord.x) % 2 == 1 && int(gl_FragCoord.y) % 2 == 1)
    discard;
  float x = gl_FragCoord.x, y = gl_FragCoord.y;
  float v = x * x + 3.0 * y * y + x * y;
  o0 = vec4(dFdxFine(v), dFdyFine(v), dFdxCoarse(v), dFdyCoarse(v));
  o1 = vec4(fwidthFine(v), fwidthCoarse(v), dFdx(v), dFdy(v));
  vec2 d2 = dFdx(vec2(x * y, y));
  o2 = vec4(d2, subgroupQuadSwapHorizontal(x), subgroupQuadBroadcast(y, 2u));
}
