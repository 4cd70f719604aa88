#version 460
// Integer, float and bool arithmetic, comparisons, bit operations and conversions, one invocation per input
// pair. The test recomputes every output on the CPU.
layout(local_size_x = 16) in;
layout(set = 0, binding = 0, std430) readonly buffer In { int a[]; } inA;
layout(set = 0, binding = 1, std430) readonly buffer In2 { int b[]; } inB;
layout(set = 0, binding = 2, std430) writeonly buffer Out { int r[]; } outI;
layout(set = 0, binding = 3, std430) writeonly buffer OutF { float f[]; } outF;

const int kOut = 24;
void main() {
  uint i = gl_GlobalInvocationID.x;
  int a = inA.a[i];
  int b = inB.b[i];
  uint ua = uint(a), ub = uint(b);
  uint o = i * kOut;
  outI.r[o + 0] = a + b;
  outI.r[o + 1] = a - b;
  outI.r[o + 2] = a * b;
  outI.r[o + 3] = b != 0 ? a / b : 0;
  outI.r[o + 4] = b != 0 ? a % b : 0;
  outI.r[o + 5] = int(ub != 0u ? ua / ub : 0u);
  outI.r[o + 6] = int(ub != 0u ? ua % ub : 0u);
  outI.r[o + 7] = a & b;
  outI.r[o + 8] = a | b;
  outI.r[o + 9] = a ^ b;
  outI.r[o + 10] = ~a;
  outI.r[o + 11] = a << (b & 31);
  outI.r[o + 12] = a >> (b & 31);
  outI.r[o + 13] = int(ua >> (ub & 31u));
  outI.r[o + 14] = (a < b ? 1 : 0) | (a <= b ? 2 : 0) | (a > b ? 4 : 0) | (a >= b ? 8 : 0) | (a == b ? 16 : 0) |
                   (a != b ? 32 : 0) | (ua < ub ? 64 : 0) | (ua > ub ? 128 : 0);
  outI.r[o + 15] = -a;
  outI.r[o + 16] = bitCount(a);
  outI.r[o + 17] = findMSB(a);
  outI.r[o + 18] = findLSB(a);
  outI.r[o + 19] = bitfieldExtract(a, 3, 7);
  outI.r[o + 20] = int(bitfieldExtract(ua, 5, 9));
  outI.r[o + 21] = bitfieldInsert(a, b, 4, 8);
  outI.r[o + 22] = int(bitfieldReverse(ua));
  bool p = a > 0, q = b > 0;
  outI.r[o + 23] = ((p && q) ? 1 : 0) | ((p || q) ? 2 : 0) | ((p != q) ? 4 : 0) | (!p ? 8 : 0);

  float fa = float(a) * 0.25, fb = float(b) * 0.5;
  uint of = i * 8;
  outF.f[of + 0] = fa + fb;
  outF.f[of + 1] = fa - fb;
  outF.f[of + 2] = fa * fb;
  outF.f[of + 3] = fb != 0.0 ? fa / fb : 0.0;
  outF.f[of + 4] = fb != 0.0 ? mod(fa, fb) : 0.0;
  outF.f[of + 5] = float(int(fa * 3.0));
  outF.f[of + 6] = float(uint(abs(fa)));
  outF.f[of + 7] = (fa < fb ? 1.0 : 0.0) + (fa >= fb ? 2.0 : 0.0) + float(ua) * 0.0;
}
