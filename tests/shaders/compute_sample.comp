#version 450
// Sampling: textureLod on a combined image sampler, on a separate texture + sampler and on a 2D array;
// texelFetch with a level; textureQueryLevels and textureSize.
layout(local_size_x = 4) in;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(set = 0, binding = 1) uniform texture2D sepTex;
layout(set = 0, binding = 2) uniform sampler sepSmp;
layout(set = 0, binding = 3) uniform sampler2DArray texArr;
layout(set = 0, binding = 4) readonly buffer In { vec4 coords[]; };  // (u, v, lod, layer)
layout(set = 0, binding = 5) buffer Out { vec4 r[]; };
layout(set = 0, binding = 6) buffer Info { ivec4 info; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec4 q = coords[i];
  r[4 * i + 0] = textureLod(tex, q.xy, q.z);
  r[4 * i + 1] = textureLod(sampler2D(sepTex, sepSmp), q.xy, q.z);
  r[4 * i + 2] = textureLod(texArr, vec3(q.xy, q.w), q.z);
  r[4 * i + 3] = texelFetch(tex, ivec2(floor(q.xy)), int(q.z));
  if (i == 0) info = ivec4(textureQueryLevels(tex), textureSize(tex, 1), textureSize(texArr, 0).z);
}
