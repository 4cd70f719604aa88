// Push descriptors in a fragment shader (tests/e2e/push_descriptor_test.cpp): the color comes from a uniform buffer
// of the push descriptor set 0.
#version 450
layout(set = 0, binding = 0) uniform Color { vec4 rgba; } color;
layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = color.rgba; }
