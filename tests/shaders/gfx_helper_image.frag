#version 450
// Image writes from helper lanes land nowhere (GraphicsShader.HelperLanesWriteNoImage).
layout(set = 0, binding = 0, r32f) uniform writeonly image2D img;
layout(location = 0) out vec4 o;
void main() {
  imageStore(img, ivec2(gl_FragCoord.xy), vec4(gl_FragCoord.x + 100.0 * gl_FragCoord.y));
  o = vec4(1.0);
}
