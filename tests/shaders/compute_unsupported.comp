#version 460
// Uses an image atomic (OpImageTexelPointer), which the compiler does not support yet: pipeline creation must
// fail with a message naming the instruction.
layout(local_size_x = 1) in;
layout(set = 0, binding = 0, r32ui) uniform uimage2D img;
void main() { imageAtomicAdd(img, ivec2(gl_GlobalInvocationID.xy), 1u); }
