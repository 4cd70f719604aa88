#version 450
// Explicit gradients in a vertex shader (GraphicsShader.GradSamplingInAVertexShader): 4 texels a unit of x on a
// 64-texel-wide level 0 ask for level 2; implicit LOD does not exist here, textureLod still works.
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(location = 0) out vec2 o;
void main() {
  o = vec2(textureGrad(tex, vec2(0.25), vec2(4.0 / 64.0, 0.0), vec2(0.0)).x, textureLod(tex, vec2(0.25), 5.0).x);
  gl_Position = vec4(0.0);
}
