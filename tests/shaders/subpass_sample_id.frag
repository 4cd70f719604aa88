#version 450
// The multisampled input attachment test's subpass 0: one invocation per sample (gl_SampleID makes the shading
// per sample), red 0.2 (sample + 1).
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(0.2 * float(gl_SampleID + 1), 0.5, 0.0, 1.0); }
