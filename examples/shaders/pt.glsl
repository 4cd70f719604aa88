// What the path tracer's shaders (pt_*) share with examples/pathtracer.cpp: the scene tables, the payloads, the
// material call's data and the random numbers. Every table is std430; the C++ structures mirror them.
struct Vertex {
  vec4 positionU;  // object-space position, texture u
  vec4 normalV;    // object-space normal (zero: none), texture v
};
// A triangle geometry: its triangles are indices[firstIndex + 3 * gl_PrimitiveID + k] + vertexOffset. A BLAS's
// geometries are geometries[gl_InstanceCustomIndexEXT + gl_GeometryIndexEXT].
struct Geometry {
  uint firstIndex;
  uint vertexOffset;
  uint material;
  uint pad;
};
// kind: the callable shader (SBT callable record) that samples its BSDF. alphaMode: 0 opaque, 1 glTF MASK
// (baseColor.a x texture alpha against alphaCutoff), 2 the procedural cutout (round holes in texture space).
struct Material {
  vec4 baseColor;
  vec4 emission;
  int texture;  // -1: none
  uint kind;
  uint alphaMode;
  float alphaCutoff;
  float roughness;
  float ior;
  uint sampledLight;  // 1: the emitter is the scene's quad light, which diffuse bounces sample directly
  float pad;
};
struct Texture {
  uint offset;  // first texel in texels[]
  uint width;
  uint height;
  uint pad;
};
struct Sphere {
  vec4 centerRadius;
  uint material;
  uint pad0;
  uint pad1;
  uint pad2;
};

const uint kDiffuse = 0u, kMetal = 1u, kGlass = 2u;

layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(set = 0, binding = 3, std430) readonly buffer Vertices { Vertex vertices[]; };
layout(set = 0, binding = 4, std430) readonly buffer Indices { uint indices[]; };
layout(set = 0, binding = 5, std430) readonly buffer Geometries { Geometry geometries[]; };
layout(set = 0, binding = 6, std430) readonly buffer Materials { Material materials[]; };
layout(set = 0, binding = 7, std430) readonly buffer Textures { Texture textures[]; };
layout(set = 0, binding = 8, std430) readonly buffer Texels { uint texels[]; };  // RGBA8, sRGB colour
layout(set = 0, binding = 9, std430) readonly buffer Spheres { Sphere spheres[]; };

// The closest hit, or t < 0 for a miss (payload location 0).
struct HitPayload {
  vec3 position;
  float t;
  vec3 normal;  // world-space shading normal (not yet facing the ray)
  uint material;
  vec3 geometricNormal;  // world space
  float pad0;
  vec3 albedo;  // the material's base colour times its texture, linear
  float pad1;
};

// executeCallableEXT's data (location 0): the material kind samples a direction after a hit.
struct BsdfSample {
  vec3 normal;  // in: the shading normal, facing the incoming ray
  uint rng;     // in/out: the random state
  vec3 incoming;  // in: the ray's direction
  uint material;  // in
  vec3 albedo;    // in
  uint frontFace;  // in: 1 when the ray met the surface's front (outside)
  vec3 direction;  // out: the sampled direction
  uint diffuse;    // out: 1 for a diffuse bounce (the light is then sampled directly)
  vec3 weight;     // out: BSDF x cosine / pdf; 0 when the path ends
  float pad;
};

// Nearest texel, repeating: integer arithmetic only, so every driver samples the same texel.
vec4 texel(int t, vec2 uv) {
  Texture tx = textures[t];
  vec2 f = uv - floor(uv);
  uint x = min(uint(f.x * float(tx.width)), tx.width - 1u), y = min(uint(f.y * float(tx.height)), tx.height - 1u);
  return unpackUnorm4x8(texels[tx.offset + y * tx.width + x]);
}

// PCG (O'Neill), one 32-bit step per number: the same sequence on every driver for a given seed.
uint pcg(inout uint state) {
  state = state * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}
float rnd(inout uint state) { return float(pcg(state) >> 8) * (1.0 / 16777216.0); }

// An orthonormal basis around n (Duff et al., "Building an Orthonormal Basis, Revisited").
void basis(vec3 n, out vec3 t, out vec3 b) {
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z), c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}
