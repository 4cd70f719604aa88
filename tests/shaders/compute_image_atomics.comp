#version 450
// Image atomics (OpImageTexelPointer) on r32ui and r32i storage images: 128 invocations over 16 texels add,
// take the minimum and race a compare-exchange; every returned value is kept for the test to check.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0, r32ui) uniform uimage2D counts;
layout(set = 0, binding = 1, r32i) uniform iimage2D minima;
layout(set = 0, binding = 2, r32ui) uniform uimage2D winners;
layout(set = 0, binding = 3) buffer Out {
  uint swapped[128];
  uint outOfBounds[128];
};

void main() {
  uint i = gl_GlobalInvocationID.x;
  ivec2 p = ivec2(i % 4u, (i / 4u) % 4u);
  imageAtomicAdd(counts, p, i + 1u);
  imageAtomicMin(minima, p, int(i) - 100);
  swapped[i] = imageAtomicCompSwap(winners, p, 0u, i + 1u);
  // Outside the image: no effect (the values returned are undefined).
  outOfBounds[i] = imageAtomicAdd(counts, ivec2(4 + int(i), 0), 5u) + imageAtomicExchange(counts, ivec2(-1, 0), 7u);
}
