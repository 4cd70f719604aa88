#version 460
// Uses a storage image, which the compiler does not support yet: pipeline creation must fail with a message
// naming the instruction.
layout(local_size_x = 1) in;
layout(set = 0, binding = 0, rgba8) uniform writeonly image2D img;
void main() { imageStore(img, ivec2(gl_GlobalInvocationID.xy), vec4(1.0)); }
