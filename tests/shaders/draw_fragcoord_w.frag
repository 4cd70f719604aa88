#version 450
// FragCoord's w and z beside an input equal at every vertex (DrawQuadShadingTest.FragCoordWWhereNothingVaries).
layout(location = 0) in vec4 vColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(gl_FragCoord.w, gl_FragCoord.z, vColor.b, vColor.a); }
