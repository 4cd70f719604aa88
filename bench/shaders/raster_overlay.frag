#version 450
// The raster benchmark's blended pass: a constant translucent colour (blended src-alpha / one-minus-src-alpha).
layout(location = 0) in vec4 inColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = inColor; }
