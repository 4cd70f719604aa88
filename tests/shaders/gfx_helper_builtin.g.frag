#version 450
// gl_HelperInvocation before and after a demotion (SPIR-V 1.6: the variable is Volatile, so a load after
// OpDemoteToHelperInvocation sees it), seen by the quad's covered lanes through fine derivatives of it (a helper
// lane's own outputs are discarded): GraphicsShader.HelperInvocationBuiltIn, on the fiber and the SPMD paths. Not
// optimized (`.g.`): glslc's optimizer merges the two loads of the variable, Volatile though it is.
#extension GL_EXT_demote_to_helper_invocation : require
layout(location = 0) flat in int demoteMe;
layout(location = 0) out vec4 color;
void main() {
  const float before = gl_HelperInvocation ? 1.0 : 0.0;
  if (demoteMe != 0) demote;
  const float after = gl_HelperInvocation ? 1.0 : 0.0;
  color = vec4(dFdxFine(before), dFdyFine(before), dFdxFine(after), dFdyFine(after));
}
