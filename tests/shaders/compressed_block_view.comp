#version 450
// An uncompressed view of a compressed image (VK_IMAGE_CREATE_BLOCK_TEXEL_VIEW_COMPATIBLE_BIT,
// tests/e2e/compressed_format_test.cpp): each invocation loads block (i % 2, i / 2) of the RGBA32UI storage view,
// writes it to the buffer and stores `replacement` in its place; invocation 0 also writes the view's size.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, rgba32ui) uniform uimage2D blocks;
layout(set = 0, binding = 1) buffer Out {
  uvec4 size;
  uvec4 loaded[4];
};
layout(push_constant) uniform P { uvec4 replacement; };

void main() {
  ivec2 b = ivec2(gl_GlobalInvocationID.x % 2, gl_GlobalInvocationID.x / 2);
  loaded[gl_GlobalInvocationID.x] = imageLoad(blocks, b);
  imageStore(blocks, b, replacement + uvec4(gl_GlobalInvocationID.x));
  if (gl_GlobalInvocationID.x == 0) size = uvec4(imageSize(blocks), 0, 0);
}
