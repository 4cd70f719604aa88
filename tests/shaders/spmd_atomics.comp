#version 450
// Atomics on the SPMD path (spmd_test.cpp, Spmd.AtomicsRunLaneByLaneInOrder): one workgroup of 64 invocations. Each
// atomic instruction runs for the invocations in their order on both paths (the SPMD path a batch's lanes in order),
// so what one instruction's results depend on is the same on both: a histogram (varying addresses, results unused), an
// append through a uniform counter (each lane its own slot), min, max, and, or, xor (unsigned and signed),
// compare-exchange and exchange chains, an add to the invocation's own word, all under divergence. (Between
// instructions the paths interleave the invocations differently, as Vulkan allows: nothing here depends on it.)
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Counters {
  uint count;
  uint minv;
  uint maxv;
  uint orv;
  uint andv;
  uint xorv;
  int smin;
  int smax;
  uint chain;
  uint exch;
  uint stored;
  uint pad;
};
layout(std430, binding = 1) buffer Hist { uint bins[16]; };
layout(std430, binding = 2) buffer Out { uint o[]; };  // 4 per invocation
layout(std430, binding = 3) buffer Items { uint items[]; };

void main() {
  const uint i = gl_LocalInvocationIndex;
  const uint v = (i * 2654435761u) >> 7;
  atomicAdd(bins[v % 16u], 1u);
  const uint s = atomicAdd(count, 1u);
  items[s] = v;
  atomicMin(minv, v);
  atomicMax(maxv, v);
  atomicOr(orv, 1u << (i % 32u));
  atomicAnd(andv, ~(1u << (i % 29u)));
  atomicXor(xorv, v);
  atomicMin(smin, int(v % 1000003u) - 500000);
  atomicMax(smax, int(v % 977u) - 500);
  const uint old = atomicCompSwap(chain, i, i + 1u);  // every invocation finds its own index: a chain 0 -> 64
  const uint e = atomicExchange(exch, i);
  if (i % 4u != 3u) {
    o[i * 4u + 0u] = s;
    atomicAdd(o[i * 4u + 3u], 5u);  // its own word: what it held, plus 5
  } else {
    atomicExchange(stored, i);
  }
  o[i * 4u + 1u] = old;
  o[i * 4u + 2u] = e;
}
