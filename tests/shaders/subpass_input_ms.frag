#version 450
// The multisampled input attachment test: sample 3 of attachment A (subpassInputMS) at the fragment's position.
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInputMS inA;
layout(location = 0) out vec4 outColor;
void main() { outColor = subpassLoad(inA, 3); }
