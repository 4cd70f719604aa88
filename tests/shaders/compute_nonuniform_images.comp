#version 450
// Image descriptor arrays indexed per invocation (GL_EXT_nonuniform_qualifier): a runtime-sized array of
// combined image samplers (texelFetch and textureLod) and an array of storage images (imageLoad, imageStore,
// imageSize); each invocation of a workgroup picks another element.
#extension GL_EXT_nonuniform_qualifier : require
layout(local_size_x = 4, local_size_y = 2) in;
layout(set = 0, binding = 0) uniform sampler2D tex[];
layout(set = 0, binding = 1, r32ui) uniform uimage2D imgs[3];
layout(set = 0, binding = 2, std430) writeonly buffer Out { vec4 o[]; };

void main() {
  uvec2 g = gl_GlobalInvocationID.xy;
  uint i = g.y * 4u + g.x;
  uint t = (i * 5u + 1u) % 4u;
  uint s = (i + g.y) % 3u;
  ivec2 at = ivec2(g);
  vec4 fetched = texelFetch(tex[nonuniformEXT(t)], at, 0);
  vec4 sampled = textureLod(tex[nonuniformEXT(t)], (vec2(at) + 0.5) / vec2(4.0, 2.0), 0.0);
  uint old = imageLoad(imgs[nonuniformEXT(s)], at).x;
  imageStore(imgs[nonuniformEXT(s)], at, uvec4(old * 2u + i));
  ivec2 size = imageSize(imgs[nonuniformEXT(s)]);
  o[i * 3u + 0u] = fetched;
  o[i * 3u + 1u] = sampled;
  o[i * 3u + 2u] = vec4(float(old), float(size.x), float(size.y), float(textureSize(tex[nonuniformEXT(t)], 0).x));
}
