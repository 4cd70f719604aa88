#version 450
// textureGrad through a sampler with anisotropic filtering and one without, on the same image
// (ComputeAnisotropyTest.GradSamplingAveragesAlongTheMajorAxis).
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform sampler2D aniso;
layout(set = 0, binding = 1) uniform sampler2D iso;
layout(set = 0, binding = 2) readonly buffer In { vec4 q[]; };  // (u, v, du/dx, dv/dy)
layout(set = 0, binding = 3) buffer Out { vec4 r[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 c = q[i];
  r[2 * i] = textureGrad(aniso, c.xy, vec2(c.z, 0.0), vec2(0.0, c.w));
  r[2 * i + 1] = textureGrad(iso, c.xy, vec2(c.z, 0.0), vec2(0.0, c.w));
}
