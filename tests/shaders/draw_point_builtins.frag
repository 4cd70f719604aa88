#version 450
// PointCoord and SampleMask of a point's one-sample fragment (DrawQuadShadingTest.PointCoordAndSampleMaskIn).
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(gl_PointCoord, 0.25 * float(gl_SampleMaskIn[0]), 1.0); }
