#version 450
// Storage images: loads and stores of rgba8, rgba32f, r32f (2D array), r32ui (3D) and rgba16f images,
// imageSize, and out-of-bounds coordinates (reads zero, writes dropped).
layout(local_size_x = 4, local_size_y = 4) in;
layout(set = 0, binding = 0, rgba8) uniform readonly image2D srcRgba8;
layout(set = 0, binding = 1, rgba32f) uniform writeonly image2D dstRgba32f;
layout(set = 0, binding = 2, r32f) uniform image2DArray arrR32f;
layout(set = 0, binding = 3, r32ui) uniform uimage3D volR32ui;
layout(set = 0, binding = 4, rgba16f) uniform image2D halfImg;
layout(set = 0, binding = 5) buffer Out {
  ivec4 sizes[4];
  vec4 oob[2];
  uvec4 oobu;
};

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  vec4 c = imageLoad(srcRgba8, p);
  imageStore(dstRgba32f, p, c * 2.0 + vec4(p, 0.0, 0.0));
  for (int l = 0; l < 3; ++l) {
    float v = imageLoad(arrR32f, ivec3(p, l)).x;
    imageStore(arrR32f, ivec3(p, l), vec4(v * 3.0 + float(l)));
  }
  for (int z = 0; z < 2; ++z) {
    uint u = imageLoad(volR32ui, ivec3(p, z)).x;
    imageStore(volR32ui, ivec3(p, z), uvec4((u ^ 0x5a5a5a5au) + uint(z)));
  }
  vec4 h = imageLoad(halfImg, p);
  imageStore(halfImg, p, h * 0.5 + vec4(c.x));
  // Out of bounds: dropped.
  imageStore(dstRgba32f, p + ivec2(8, 0), vec4(99.0));
  imageStore(dstRgba32f, ivec2(-1 - p.x, p.y), vec4(99.0));
  imageStore(arrR32f, ivec3(p, 3), vec4(99.0));
  imageStore(volR32ui, ivec3(p, -1), uvec4(99u));
  if (p == ivec2(0)) {
    sizes[0] = ivec4(imageSize(srcRgba8), 0, 0);
    sizes[1] = ivec4(imageSize(arrR32f), 0);
    sizes[2] = ivec4(imageSize(volR32ui), 0);
    sizes[3] = ivec4(imageSize(halfImg), 0, 0);
    oob[0] = imageLoad(srcRgba8, ivec2(8, 0));
    oob[1] = imageLoad(arrR32f, ivec3(0, 0, 5));
    oobu = imageLoad(volR32ui, ivec3(0, 1000000, 0));
  }
}
