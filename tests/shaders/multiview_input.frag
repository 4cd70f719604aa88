#version 450
#extension GL_EXT_multiview : require
// Multiview with an input attachment: each view reads its own layer of attachment A and adds its view index to blue.
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInput inA;
layout(location = 0) out vec4 outColor;
void main() {
  vec4 a = subpassLoad(inA);
  outColor = vec4(a.r, a.g, 0.25 * float(gl_ViewIndex + 1), 1.0);
}
