#version 450
// Every vertex built-in (GraphicsShader.VertexBuiltIns).
#extension GL_ARB_shader_draw_parameters : require
#extension GL_EXT_multiview : require
layout(location = 0) flat out ivec4 a;
layout(location = 1) flat out ivec2 b;
void main() {
  a = ivec4(gl_VertexIndex, gl_InstanceIndex, gl_BaseVertexARB, gl_BaseInstanceARB);
  b = ivec2(gl_DrawIDARB, int(gl_ViewIndex));
  gl_Position = vec4(float(gl_VertexIndex), 0.0, 0.0, 1.0);
}
