#version 450
// Cube map sampling: textureLod and textureGather on a samplerCube, and textureLod on the second cube of a
// samplerCubeArray.
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform samplerCube cube;
layout(set = 0, binding = 1) readonly buffer In { vec4 dirs[]; };  // (x, y, z, lod)
layout(set = 0, binding = 2) buffer Out { vec4 r[]; };
layout(set = 0, binding = 3) uniform samplerCubeArray cubes;
void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 q = dirs[i];
  r[3 * i + 0] = textureLod(cube, q.xyz, q.w);
  r[3 * i + 1] = textureGather(cube, q.xyz, 0);
  r[3 * i + 2] = textureLod(cubes, vec4(q.xyz, 1.2), q.w);
}
