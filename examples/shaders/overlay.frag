#version 460
// hybrid: the overlay's colour, blended over the scene (SRC_ALPHA, ONE_MINUS_SRC_ALPHA).
layout(location = 0) out vec4 color;
void main() { color = vec4(0.05, 0.08, 0.2, 0.6); }
