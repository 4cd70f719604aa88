#version 450
// 1D storage images and a 1D sampler (capabilities Image1D, Sampled1D) with formats of the "storage image extended
// formats" (StorageImageExtendedFormats): rg16f and rg8_snorm declared, read and written; r8 sampled.
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, rg16f) uniform image1D halves;
layout(set = 0, binding = 1, rg8_snorm) uniform image1DArray snorms;
layout(set = 0, binding = 2) uniform sampler1D bytes;
layout(set = 0, binding = 3) buffer Out {
  vec4 sampled[8];
  ivec4 sizes;
};

void main() {
  int x = int(gl_GlobalInvocationID.x);
  vec4 h = imageLoad(halves, x);
  imageStore(halves, x, vec4(h.x * 2.0 + 0.5, h.y - float(x), 7.0, 7.0));
  for (int l = 0; l < 2; ++l) {
    vec2 s = imageLoad(snorms, ivec2(x, l)).xy;
    imageStore(snorms, ivec2(x, l), vec4(-s.x * 0.5 + float(l) * 0.25, s.y, 0.0, 0.0));
  }
  sampled[x] = textureLod(bytes, (float(x) + 0.5) / 8.0, 0.0);
  if (x == 0) sizes = ivec4(imageSize(halves), imageSize(snorms), textureSize(bytes, 0));
}
