// Triangle meshes made of quads and boxes, with a normal and a material per triangle: the scenes of scene_demo and
// hybrid.
#pragma once

#include <cstdint>
#include <vector>

namespace example {

struct Mesh {
  std::vector<float> vertices;  // xyz
  std::vector<uint32_t> indices;
  std::vector<float> triangles;  // per triangle: object-space normal xyz, material
  void quad(const float a[3], const float b[3], const float c[3], const float d[3], uint32_t material) {
    // a b c d counter-clockwise seen from the side the normal points to.
    uint32_t base = uint32_t(vertices.size() / 3);
    for (const float* v : {a, b, c, d}) vertices.insert(vertices.end(), v, v + 3);
    indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 2; ++k) triangles.insert(triangles.end(), {n[0], n[1], n[2], float(material)});
  }
  void box(float sx, float sy, float sz, uint32_t material) {  // centred on x and z, from y = 0 to sy
    const float x = sx / 2, z = sz / 2;
    const float p[8][3] = {{-x, 0, -z}, {x, 0, -z}, {x, sy, -z}, {-x, sy, -z},
                           {-x, 0, z},  {x, 0, z},  {x, sy, z},  {-x, sy, z}};
    quad(p[4], p[5], p[6], p[7], material);  // front (+z)
    quad(p[1], p[0], p[3], p[2], material);  // back
    quad(p[5], p[1], p[2], p[6], material);  // right
    quad(p[0], p[4], p[7], p[3], material);  // left
    quad(p[7], p[6], p[2], p[3], material);  // top
    quad(p[0], p[1], p[5], p[4], material);  // bottom
  }
};

}  // namespace example
