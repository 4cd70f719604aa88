// A 32-bit integer hash (xor-shift-multiply, "lowbias32"); bench_common.hpp's hash32() is the same on the C++ side.
uint hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
