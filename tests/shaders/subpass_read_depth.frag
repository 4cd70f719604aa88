#version 450
// Reads the depth attachment of its own subpass as an input attachment (a feedback loop ordered by barriers
// between draws) and writes it as red.
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInput inDepth;
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(subpassLoad(inDepth).r, 0.0, 0.0, 1.0); }
