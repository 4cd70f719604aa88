#version 450
// Subpass 0 of the input attachment test: a color that depends on the pixel, (x + 0.5) / 32, (y + 0.5) / 32.
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(gl_FragCoord.x / 32.0, gl_FragCoord.y / 32.0, 0.5, 1.0); }
