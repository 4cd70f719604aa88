// A closest-hit shader of realistic size for the pipeline creation benchmark (bench/pipeline_bench.cpp): a
// procedural material (value-noise fBm, a GGX specular term). The specialization constant makes each stage and each
// timed creation a distinct shader to compile.
#version 460
#extension GL_EXT_ray_tracing : require

layout(constant_id = 0) const uint kVariant = 0;
layout(location = 0) rayPayloadInEXT vec4 payload;
hitAttributeEXT vec2 bary;

uint hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

float lattice(ivec3 c) { return float(hash(uint(c.x) ^ hash(uint(c.y) ^ hash(uint(c.z) + kVariant)))) / 4294967295.0; }

float noise(vec3 p) {
  ivec3 c = ivec3(floor(p));
  vec3 f = fract(p);
  vec3 u = f * f * (3.0 - 2.0 * f);
  float x00 = mix(lattice(c), lattice(c + ivec3(1, 0, 0)), u.x);
  float x10 = mix(lattice(c + ivec3(0, 1, 0)), lattice(c + ivec3(1, 1, 0)), u.x);
  float x01 = mix(lattice(c + ivec3(0, 0, 1)), lattice(c + ivec3(1, 0, 1)), u.x);
  float x11 = mix(lattice(c + ivec3(0, 1, 1)), lattice(c + ivec3(1, 1, 1)), u.x);
  return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

float fbm(vec3 p) {
  float sum = 0.0, amp = 0.5;
  for (int i = 0; i < 6; ++i) {
    sum += amp * noise(p);
    p = p * 2.03 + vec3(1.7, 9.2, 3.1);
    amp *= 0.5;
  }
  return sum;
}

float ggx(vec3 n, vec3 v, vec3 l, float roughness) {
  vec3 h = normalize(v + l);
  float a2 = roughness * roughness * roughness * roughness;
  float nh = max(dot(n, h), 0.0);
  float d = nh * nh * (a2 - 1.0) + 1.0;
  float nv = max(dot(n, v), 1e-4), nl = max(dot(n, l), 1e-4);
  float k = (roughness + 1.0) * (roughness + 1.0) / 8.0;
  float g = nv / (nv * (1.0 - k) + k) * nl / (nl * (1.0 - k) + k);
  float fresnel = 0.04 + 0.96 * pow(1.0 - max(dot(h, v), 0.0), 5.0);
  return a2 / (3.14159265 * d * d) * g * fresnel / (4.0 * nv * nl);
}

void main() {
  vec3 p = gl_WorldRayOriginEXT + gl_HitTEXT * gl_WorldRayDirectionEXT;
  vec3 n = normalize(vec3(bary, 1.0 - bary.x - bary.y) * 2.0 - 1.0);
  float t = fbm(p * (1.0 + float(kVariant & 7u)));
  vec3 albedo = mix(vec3(0.8, 0.2, 0.1), vec3(0.1, 0.3, 0.9), t);
  vec3 l = normalize(vec3(0.3, 1.0, 0.2));
  vec3 v = -gl_WorldRayDirectionEXT;
  float spec = ggx(n, v, l, 0.2 + 0.6 * t);
  payload = vec4(albedo * max(dot(n, l), 0.0) + vec3(spec), 1.0);
}
