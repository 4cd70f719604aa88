#version 450
// An integer output at location 0 (ColorMerge.*): nothing for the 8-bit UNorm writes to encode, so no merge.
layout(location = 0) flat in uvec4 inColor;
layout(location = 0) out uvec4 outColor;
void main() { outColor = inColor + 1u; }
