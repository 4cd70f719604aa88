#version 460
// GLSL.std.450 functions on floats and vectors.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer In { float x[]; } inp;
layout(set = 0, binding = 1, std430) writeonly buffer Out { float r[]; } outp;

const uint kOut = 32;
void main() {
  uint i = gl_GlobalInvocationID.x;
  float x = inp.x[i];
  float y = inp.x[i + 1u];
  uint o = i * kOut;
  outp.r[o + 0] = sin(x);
  outp.r[o + 1] = cos(x);
  outp.r[o + 2] = tan(x * 0.3);
  outp.r[o + 3] = exp(x * 0.5);
  outp.r[o + 4] = log(abs(x) + 1.0);
  outp.r[o + 5] = pow(abs(x) + 0.5, 1.7);
  outp.r[o + 6] = sqrt(abs(x));
  outp.r[o + 7] = inversesqrt(abs(x) + 1.0);
  outp.r[o + 8] = floor(x);
  outp.r[o + 9] = ceil(x);
  outp.r[o + 10] = fract(x);
  outp.r[o + 11] = clamp(x, -1.0, 1.5);
  outp.r[o + 12] = mix(x, y, 0.25);
  outp.r[o + 13] = step(0.5, x);
  outp.r[o + 14] = smoothstep(-1.0, 2.0, x);
  outp.r[o + 15] = atan(x, y + 3.0);
  outp.r[o + 16] = min(x, y);
  outp.r[o + 17] = max(x, y);
  outp.r[o + 18] = sign(x);
  outp.r[o + 19] = round(x);
  outp.r[o + 20] = trunc(x);
  outp.r[o + 21] = exp2(x * 0.5);
  outp.r[o + 22] = log2(abs(x) + 1.0);
  outp.r[o + 23] = asin(clamp(x * 0.2, -1.0, 1.0));
  vec3 a = vec3(x, y, 1.0), b = vec3(y, 2.0, x);
  outp.r[o + 24] = length(a);
  outp.r[o + 25] = distance(a, b);
  outp.r[o + 26] = dot(a, b);
  vec3 c = cross(a, b);
  outp.r[o + 27] = c.x + 2.0 * c.y + 3.0 * c.z;
  vec3 n = normalize(a);
  outp.r[o + 28] = n.x + 2.0 * n.y + 3.0 * n.z;
  vec3 rf = reflect(a, normalize(b));
  outp.r[o + 29] = rf.x + 2.0 * rf.y + 3.0 * rf.z;
  outp.r[o + 30] = fma(x, y, 1.0);
  outp.r[o + 31] = radians(x) + degrees(y);
}
