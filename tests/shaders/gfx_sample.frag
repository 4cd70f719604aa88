#version 450
// Implicit-LOD sampling picks the mip the coordinates' derivatives ask for (GraphicsShader.ImplicitLodSampling).
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(location = 0) noperspective in vec2 uv;
layout(location = 0) out vec4 color;
layout(location = 1) out vec4 biased;
layout(location = 2) out vec4 graded;
void main() {
  color = texture(tex, uv);
  biased = texture(tex, uv, 1.0);
  graded = textureGrad(tex, uv, vec2(1.0 / 16.0, 0.0), vec2(0.0, 1.0 / 16.0));
}
