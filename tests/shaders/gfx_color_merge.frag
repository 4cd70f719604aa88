#version 450
// The SPMD entry's colour attachment writes (ColorMerge.*): the colour comes in as it goes out.
layout(location = 0) in vec4 inColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = inColor; }
