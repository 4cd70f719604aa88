#version 450
#extension GL_EXT_shader_image_load_formatted : require
// Storage images declared without a format (Image Format Unknown: StorageImageReadWithoutFormat and
// StorageImageWriteWithoutFormat): each texel converts from or to the format of the view bound when the shader
// runs, so one pipeline serves views of any storage format (tests/spirv/formatless_reference.hpp computes the
// expected texels). `src` is read only, `dst` written only (no qualifier, as ray tracing samples declare their
// output image), `acc` and `ids` are read and written back.
layout(local_size_x = 4, local_size_y = 4) in;
layout(set = 0, binding = 0) uniform readonly image2D src;
layout(set = 0, binding = 1) uniform image2D dst;
layout(set = 0, binding = 2) uniform image2D acc;
layout(set = 0, binding = 3) uniform uimage2D ids;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  vec4 c = imageLoad(src, p);
  imageStore(dst, p, c.bgra * 0.5 + vec4(float(p.x) * 0.125, float(p.y) * 0.0625, 0.25, -0.125));
  imageStore(acc, p, imageLoad(acc, p) + c);
  imageStore(ids, p, imageLoad(ids, p) * 3u + uvec4(uint(p.x + 8 * p.y)));
}
