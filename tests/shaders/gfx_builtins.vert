#version 450
// Every vertex built-in (GraphicsShader.VertexBuiltIns).
#extension GL_ARB_shader_draw_parameters : require
#extension GL_EXT_multiview : require
#extension GL_KHR_shader_subgroup_basic : require
layout(location = 0) flat out ivec4 a;
layout(location = 1) flat out ivec3 b;
void main() {
  a = ivec4(gl_VertexIndex, gl_InstanceIndex, gl_BaseVertexARB, gl_BaseInstanceARB);
  b = ivec3(gl_DrawIDARB, int(gl_ViewIndex), int(gl_SubgroupSize));  // subgroups of one invocation
  gl_Position = vec4(float(gl_VertexIndex), 0.0, 0.0, 1.0);
}
