#version 450
// Derivatives, discard and demotion drawn (DrawQuadShadingTest): the derivatives are taken first, in uniform control
// flow, then some fragments discard and others demote; the rest write the derivatives, scaled into [0, 1].
#extension GL_EXT_demote_to_helper_invocation : require
layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() {
  float x = gl_FragCoord.x, y = gl_FragCoord.y;
  vec4 d = vec4(dFdxFine(x * x), dFdyCoarse(y * y), fwidthFine(x * y), 64.0 * vColor.a) / 64.0;
  int px = int(x), py = int(y);
  if ((px + 2 * py) % 5 == 0) discard;
  if ((3 * px + py) % 7 == 0) demote;
  outColor = helperInvocationEXT() ? vec4(1.0) : d;
}
