#version 450
// Inputs at locations that are not the fragment stage's slots in order (DrawQuadShadingTest.
// InputsAtSparseLocationsReachTheirVariables): the color at location 2, a position-derived vec4 at location 5 and a
// float at location 1 component 2; location 3 is written and not read.
layout(location = 0) in vec2 inPos;
layout(location = 1) in vec4 inColor;
layout(location = 2) out vec4 vColor;
layout(location = 5) out vec4 vPos;
layout(location = 1, component = 2) out float vScale;
layout(location = 3) out vec4 vUnused;
void main() {
  gl_Position = vec4(inPos, 0.0, 1.0);
  vColor = inColor;
  vPos = vec4(inPos * 0.25 + 0.5, 0.25, 1.0);
  vScale = 0.5;
  vUnused = vec4(1.0);
}
