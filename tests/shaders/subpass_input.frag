#version 450
// Subpass 1 of the input attachment test: reads attachment A at the fragment's position (subpassLoad) and writes
// (1 - r, g / 2, b, 1) to attachment B.
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInput inA;
layout(location = 0) out vec4 outColor;
void main() {
  vec4 a = subpassLoad(inA);
  outColor = vec4(1.0 - a.r, a.g * 0.5, a.b, 1.0);
}
