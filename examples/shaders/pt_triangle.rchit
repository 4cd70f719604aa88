#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
// A triangle mesh hit: the interpolated normal and texture coordinates, the material's base colour and texture.
#include "pt.glsl"
#include "pt_triangle.glsl"
layout(location = 0) rayPayloadInEXT HitPayload hit;
void main() {
  Surface s = surface();
  // Normals go to world space by the inverse transpose of the object-to-world matrix.
  mat3 normalMatrix = transpose(mat3(gl_WorldToObjectEXT));
  vec3 ng = normalize(normalMatrix *
                      cross(s.objectPosition[1] - s.objectPosition[0], s.objectPosition[2] - s.objectPosition[0]));
  vec3 n = dot(s.normal, s.normal) > 1e-12 ? normalize(normalMatrix * s.normal) : ng;
  Material m = materials[s.material];
  vec3 albedo = m.baseColor.rgb;
  if (m.texture >= 0) albedo *= pow(texel(m.texture, s.uv).rgb, vec3(2.2));
  hit.position = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  hit.t = gl_HitTEXT;
  hit.normal = n;
  hit.material = s.material;
  hit.geometricNormal = ng;
  hit.albedo = albedo;
}
