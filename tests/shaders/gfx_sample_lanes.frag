#version 450
// Gradient sampling by the lanes a discard left (GraphicsShaderSampling.*QuadSamplingByTheLanesLeft): each lane's own
// gradient picks its own level of the image whose mip m holds m.
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(location = 0) noperspective in vec2 uv;
layout(location = 1) flat in float grad;
layout(location = 2) flat in int leave;
layout(location = 0) out vec4 color;
void main() {
  if (leave != 0) discard;
  color = textureGrad(tex, uv, vec2(grad, 0.0), vec2(0.0, grad));
}
