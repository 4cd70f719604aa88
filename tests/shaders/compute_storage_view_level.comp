#version 450
// Storage image views of one level and layer that is not the image's first (StorageImageViewOfOneLevelAndLayer): each
// invocation reads its texel of both views, then, after the workgroup's barrier, writes it. Coordinates run from -2
// to 5 over views of 4x4 texels, so a quarter of the invocations address texels inside each view.
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba8) uniform image2D color;
layout(set = 0, binding = 1, r32ui) uniform uimage2D ids;
layout(set = 0, binding = 2) buffer Out {
  vec4 loaded[64];
  uint loadedIds[64];
};
layout(push_constant) uniform Values {
  vec4 value[8];  // the colour written at texel (x, y) of the view: value[(y * 4 + x) % 8] (edge cases)
};

void main() {
  const ivec2 p = ivec2(gl_LocalInvocationID.xy) - ivec2(2);
  const uint i = gl_LocalInvocationIndex;
  loaded[i] = imageLoad(color, p);
  loadedIds[i] = imageLoad(ids, p).x;
  barrier();
  imageStore(color, p, value[uint(p.y * 4 + p.x) % 8u]);
  imageStore(ids, p, uvec4(1000u + i));
}
