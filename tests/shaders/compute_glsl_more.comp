#version 450
// The GLSL.std.450 functions compute_glsl.comp does not reach: RoundEven, the inverse and hyperbolic
// trigonometry, FaceForward, Refract, Determinant and MatrixInverse (2x2, 3x3, 4x4, float and double), Modf,
// the signed and unsigned integer Abs/Sign/Min/Max/Clamp and FindUMsb, and double-precision libm calls.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer Floats { vec2 x[]; };
layout(set = 0, binding = 1, std430) readonly buffer Ints { ivec2 k[]; };
layout(set = 0, binding = 2, std430) readonly buffer Mats { mat4 m[]; };
layout(set = 0, binding = 3, std430) readonly buffer Doubles { double d[]; };
layout(set = 0, binding = 4, std430) writeonly buffer OutF { float of[]; };
layout(set = 0, binding = 5, std430) writeonly buffer OutI { int oi[]; };
layout(set = 0, binding = 6, std430) writeonly buffer OutD { double od[]; };

const uint kF = 52, kI = 12, kD = 8;

void main() {
  uint i = gl_GlobalInvocationID.x;
  float a = x[i].x, b = x[i].y;
  uint o = i * kF;
  of[o + 0] = roundEven(a);
  of[o + 1] = acos(clamp(b * 0.3, -1.0, 1.0));
  of[o + 2] = atan(a);
  of[o + 3] = sinh(b * 0.5);
  of[o + 4] = cosh(b * 0.5);
  of[o + 5] = tanh(b * 0.5);
  of[o + 6] = asinh(a);
  of[o + 7] = acosh(abs(a) + 1.0);
  of[o + 8] = atanh(clamp(b * 0.3, -0.99, 0.99));
  vec3 n = vec3(a, b, 1.0), v = vec3(b, -1.0, a), nref = vec3(1.0, a, b);
  vec3 ff = faceforward(n, v, nref);
  vec3 rr = refract(normalize(v), normalize(n), 0.66);
  vec3 rt = refract(normalize(vec3(1.0, -0.1, a * 0.01)), vec3(0.0, 1.0, 0.0), 1.5 + abs(b));  // total internal reflection
  for (int c = 0; c < 3; ++c) {
    of[o + 9 + c] = ff[c];
    of[o + 12 + c] = rr[c];
    of[o + 15 + c] = rt[c];
  }
  mat4 M = m[i];
  of[o + 18] = determinant(mat2(M));
  of[o + 19] = determinant(mat3(M));
  of[o + 20] = determinant(M);
  mat2 i2 = inverse(mat2(M));
  mat3 i3 = inverse(mat3(M));
  mat4 i4 = inverse(M);
  for (int c = 0; c < 2; ++c)
    for (int r = 0; r < 2; ++r) of[o + 21 + c * 2 + r] = i2[c][r];
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) of[o + 25 + c * 3 + r] = i3[c][r];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) of[o + 34 + c * 4 + r] = i4[c][r];
  float whole;
  of[o + 50] = modf(a, whole);
  of[o + 51] = whole;

  int p = k[i].x, q = k[i].y;
  uint up = uint(p), uq = uint(q);
  uint t = i * kI;
  oi[t + 0] = abs(p);
  oi[t + 1] = sign(p);
  oi[t + 2] = min(p, q);
  oi[t + 3] = max(p, q);
  oi[t + 4] = clamp(p, -100, 100);
  oi[t + 5] = int(min(up, uq));
  oi[t + 6] = int(max(up, uq));
  oi[t + 7] = int(clamp(up, 10u, 1000000u));
  oi[t + 8] = findMSB(up);
  ivec2 vmin = min(ivec2(p, q), ivec2(q, -p));
  oi[t + 9] = vmin.x;
  oi[t + 10] = vmin.y;
  oi[t + 11] = abs(ivec2(q, p)).x;

  double dv = d[i];
  uint s = i * kD;
  od[s + 0] = roundEven(dv);
  od[s + 1] = sqrt(abs(dv));
  dmat3 dm = dmat3(M);
  od[s + 2] = determinant(dm);
  dmat4 di = inverse(dmat4(M));
  od[s + 3] = di[0][0];
  od[s + 4] = di[3][1];
  od[s + 5] = di[2][3];
  od[s + 6] = fma(dv, dv, 1.0lf);
  od[s + 7] = clamp(dv, -1.0lf, 2.0lf);
}
