#version 460
// Atomics on a storage buffer: a global counter, min, max, or, xor, a per-bucket histogram, exchange and
// compare-exchange.
layout(local_size_x = 32) in;
layout(set = 0, binding = 0, std430) buffer Counters {
  uint count;
  uint minV;
  uint maxV;
  uint orV;
  uint xorV;
  int sminV;
  uint exch;
  uint cas;
  uint hist[16];
} c;
layout(set = 0, binding = 1, std430) buffer Old { uint old[]; } o;

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint v = (i * 2654435761u) >> 7;
  o.old[i] = atomicAdd(c.count, 1u);
  atomicMin(c.minV, v);
  atomicMax(c.maxV, v);
  atomicOr(c.orV, 1u << (i % 32u));
  atomicXor(c.xorV, v);
  atomicMin(c.sminV, int(v) - 1000000);
  atomicAdd(c.hist[v % 16u], 1u);
  atomicExchange(c.exch, 7u);
  atomicCompSwap(c.cas, 0u, i + 1u);
}
