#version 450
// Demotion and termination (DrawTerminationTest): the color is written first; fragments left of x = 16 are then
// demoted to helpers and those above y = 8 (right of x = 16) are terminated, so neither may reach the target.
#extension GL_EXT_demote_to_helper_invocation : require
#extension GL_EXT_terminate_invocation : require
layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vColor;
  if (gl_FragCoord.x < 16.0) demote;
  if (gl_FragCoord.y < 8.0) terminateInvocation;
  outColor = vColor.bgra;
}
