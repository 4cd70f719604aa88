#version 460
// dst(x, y) = src(x - 1, y) + src(x, y) + src(x + 1, y) between two size x size R32_SFLOAT storage images, the
// neighbours clamped to the image (every access inside).
layout(local_size_x = 16, local_size_y = 16) in;
layout(set = 0, binding = 0, r32f) readonly uniform image2D src;
layout(set = 0, binding = 1, r32f) writeonly uniform image2D dst;
layout(push_constant) uniform Push { int size; } pc;
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 l = ivec2(max(p.x - 1, 0), p.y), r = ivec2(min(p.x + 1, pc.size - 1), p.y);
  imageStore(dst, p, vec4(imageLoad(src, l).x + imageLoad(src, p).x + imageLoad(src, r).x));
}
