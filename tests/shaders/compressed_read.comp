#version 450
// Reads of a compressed image (tests/e2e/compressed_format_test.cpp): mode 0, texelFetch of texel
// (i % width, i / width) of level `lod`; mode 1, textureLod at coords[i] (u, v, lod); mode 2, textureGather of
// component 0 at coords[i].
layout(local_size_x = 16) in;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(set = 0, binding = 1) readonly buffer In { vec4 coords[]; };
layout(set = 0, binding = 2) buffer Out { vec4 r[]; };
layout(push_constant) uniform P {
  int mode;
  int count;
  int width;
  int lod;
};

void main() {
  int i = int(gl_GlobalInvocationID.x);
  if (i >= count) return;
  if (mode == 0)
    r[i] = texelFetch(tex, ivec2(i % width, i / width), lod);
  else if (mode == 1)
    r[i] = textureLod(tex, coords[i].xy, coords[i].z);
  else
    r[i] = textureGather(tex, coords[i].xy, 0);
}
