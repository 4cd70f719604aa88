#version 450
// Texel buffers (core Vulkan 1.0): texelFetch from uniform texel buffers of a normalized and an integer format,
// imageStore to a float storage texel buffer, imageLoad / imageAtomicAdd on an r32ui one, and the sizes
// (textureSize / imageSize). 32 invocations: those past a view's last texel read zeros and write nothing.
layout(local_size_x = 32) in;
layout(set = 0, binding = 0) uniform samplerBuffer unormTexels;  // R8G8B8A8_UNORM
layout(set = 0, binding = 1) uniform isamplerBuffer intTexels;   // R16_SINT
layout(set = 0, binding = 2, rgba32f) uniform writeonly imageBuffer floatOut;
layout(set = 0, binding = 3, r32ui) uniform uimageBuffer counters;
layout(set = 0, binding = 4, std430) writeonly buffer Out {
  int sizes[4];
  uint loaded[32];
  uint returned[32];
};

void main() {
  int i = int(gl_GlobalInvocationID.x);
  vec4 u = texelFetch(unormTexels, i);
  ivec4 n = texelFetch(intTexels, i);
  imageStore(floatOut, i, u * 2.0 + vec4(n));
  loaded[i] = imageLoad(counters, i + 4).x;
  returned[i] = imageAtomicAdd(counters, i % 4, uint(i + 1));
  if (i == 0) {
    sizes[0] = textureSize(unormTexels);
    sizes[1] = textureSize(intTexels);
    sizes[2] = imageSize(floatOut);
    sizes[3] = imageSize(counters);
  }
}
