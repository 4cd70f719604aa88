// Counts the fragments shaded at each pixel of a 32 x 32 area in a storage buffer, adding the interpolated alpha
// (1 in the tests): a shader for draws that write no attachment.
#version 450
layout(set = 0, binding = 0, std430) buffer Counts { uint count[]; };
layout(location = 0) in vec4 vColor;
void main() {
  atomicAdd(count[uint(gl_FragCoord.y) * 32u + uint(gl_FragCoord.x)], uint(vColor.a + 0.5));
}
