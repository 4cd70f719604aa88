#version 460
// hybrid: the overlay band across the top of the image, from the vertex index alone (no vertex buffer): a triangle
// strip of four vertices covering y in [-1, -0.75] in clip space.
void main() {
  vec2 corner = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1));
  gl_Position = vec4(corner.x * 2.0 - 1.0, -1.0 + corner.y * 0.25, 0.0, 1.0);
}
