#version 450
// Image accesses outside the image (robustImageAccess, VK_EXT_image_robustness): invocation i loads, stores and
// fetches at coordinate kAt[i] of a 4x4 storage image and a 4x4 texture of 2 levels (the last one inside), and
// fetches at level 2 + i, past the texture's last level.
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform image2D img;
layout(set = 0, binding = 1) uniform sampler2D tex;
layout(set = 0, binding = 2, std430) writeonly buffer Out { vec4 o[]; };

const ivec2 kAt[8] = ivec2[](ivec2(-1, 0), ivec2(4, 0), ivec2(0, -1), ivec2(0, 4), ivec2(-100, 2), ivec2(2, 100),
                            ivec2(4, 4), ivec2(1, 2));

void main() {
  uint i = gl_GlobalInvocationID.x;
  ivec2 at = kAt[i];
  o[i * 3u + 0u] = imageLoad(img, at);
  imageStore(img, at, vec4(99.0, 98.0, 97.0, 96.0));
  o[i * 3u + 1u] = texelFetch(tex, at, 0);
  o[i * 3u + 2u] = texelFetch(tex, ivec2(0, 0), 2 + int(i));
}
