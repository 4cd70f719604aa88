// What the scene demo's shaders share: the payloads and the scene tables (examples/scene_demo.cpp fills them).
struct RadiancePayload {
  vec3 color;
  uint depth;
};
// A triangle's object-space normal and material, at triangles[instance custom index + gl_PrimitiveID]; a sphere's
// object-space centre and radius at spheres[gl_PrimitiveID], its material at gl_InstanceCustomIndexEXT.
struct Triangle { vec4 normalMaterial; };
struct Material { vec4 albedo; };  // rgb, a = how much it reflects like a mirror
layout(binding = 0, set = 0) uniform accelerationStructureEXT scene;
layout(binding = 2, set = 0, std430) readonly buffer Triangles { Triangle triangles[]; };
layout(binding = 3, set = 0, std430) readonly buffer Spheres { vec4 spheres[]; };
layout(binding = 4, set = 0, std430) readonly buffer Materials { Material materials[]; };

const vec3 kLight = vec3(0.0, 1.95, 0.0);   // a small light under the ceiling
const vec3 kLightColor = vec3(1.0, 0.95, 0.85);
