#version 450
// Each fragment of a 32 x 32 target reads the texel of a 4 x 4 storage image at its own position
// (tests/e2e/shader_debug_test.cpp: ShaderImageChecksDrawTest): outside the top-left 4 x 4 pixels, line 8 reads
// outside the view.
layout(set = 0, binding = 0, r32ui) uniform readonly uimage2D img;
layout(location = 0) out vec4 color;
void main() {
  uint v = imageLoad(img, ivec2(gl_FragCoord.xy)).x;
  color = vec4(float(v) / 255.0, 0.0, 0.0, 1.0);
}
