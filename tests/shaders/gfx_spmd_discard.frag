#version 450
// Discard and demotion per lane of a quad, helper lanes' buffer stores, helperInvocationEXT() and derivatives
// taken after a demotion (GraphicsShader.QuadDiscardDemoteAndHelpers, on the fiber and the SPMD paths).
#extension GL_EXT_demote_to_helper_invocation : require
layout(location = 0) flat in int mode;  // 1: discard, 2: demote
layout(location = 0) out vec4 color;
layout(set = 0, binding = 0) buffer B { uint v[]; } buf;
void main() {
  float x = gl_FragCoord.x, y = gl_FragCoord.y;
  color = vec4(1.0);
  if (mode == 1) discard;
  if (mode == 2) demote;
  buf.v[int(x) % 2 + 2 * (int(y) % 2)] = helperInvocationEXT() ? 7u : 5u;
  color = vec4(2.0, helperInvocationEXT() ? 1.0 : 0.0, dFdx(x * x), dFdyCoarse(x * y));
}
