#version 450
// InterpolateAtOffset / Sample / Centroid of the vertex color (GLSL.std.450 76-78), one per channel.
layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vec4(interpolateAtOffset(vColor, vec2(-0.5, 0.4375)).r, interpolateAtSample(vColor, 0).g,
                  interpolateAtCentroid(vColor).b, 1.0);
}
