#version 450
// Implicit-LOD sampling of a cube map (GraphicsShaderCubeSampling): the direction (1, 1 - 2v, 1 - 2u) has s = u and
// t = v on the +X face, so the level of detail follows uv's derivatives as for gfx_sample.frag's 2D image.
layout(set = 0, binding = 0) uniform samplerCube tex;
layout(location = 0) noperspective in vec2 uv;
layout(location = 0) out vec4 color;
layout(location = 1) out vec4 biased;
layout(location = 2) out vec4 graded;
void main() {
  vec3 d = vec3(1.0, 1.0 - 2.0 * uv.y, 1.0 - 2.0 * uv.x);
  color = texture(tex, d);
  biased = texture(tex, d, 1.0);
  graded = textureGrad(tex, d, vec3(0.0, 0.0, -2.0 / 16.0), vec3(0.0, -2.0 / 16.0, 0.0));
}
