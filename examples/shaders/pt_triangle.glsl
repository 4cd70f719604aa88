// A triangle's vertices, interpolated at the hit's barycentrics (the closest-hit and any-hit shaders').
hitAttributeEXT vec2 barycentrics;

struct Surface {
  vec3 objectPosition[3];
  vec3 normal;  // object space, interpolated; zero when the mesh has none
  vec2 uv;
  uint material;
};

Surface surface() {
  Geometry g = geometries[gl_InstanceCustomIndexEXT + gl_GeometryIndexEXT];
  vec3 w = vec3(1.0 - barycentrics.x - barycentrics.y, barycentrics.x, barycentrics.y);
  Surface s;
  s.normal = vec3(0.0);
  s.uv = vec2(0.0);
  for (int k = 0; k < 3; ++k) {
    Vertex v = vertices[indices[g.firstIndex + 3u * uint(gl_PrimitiveID) + uint(k)] + g.vertexOffset];
    s.objectPosition[k] = v.positionU.xyz;
    s.normal += w[k] * v.normalV.xyz;
    s.uv += w[k] * vec2(v.positionU.w, v.normalV.w);
  }
  s.material = g.material;
  return s;
}
