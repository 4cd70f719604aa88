#version 450
// Fragment built-ins and interpolation decorations (GraphicsShader.FragmentBuiltIns).
#extension GL_EXT_multiview : require
layout(location = 0) flat in int f;
layout(location = 1) noperspective centroid in vec2 np;
layout(location = 1, component = 2) noperspective centroid in float ce;
layout(location = 2) sample in vec4 sa;
layout(location = 0) out vec4 o0;
layout(location = 1) out ivec4 o1;
layout(location = 2) out vec4 o2;
layout(location = 3) out uvec4 o3;
void main() {
  o0 = gl_FragCoord;
  o1 = ivec4(gl_FrontFacing ? 1 : 0, gl_PrimitiveID, gl_SampleID, gl_SampleMaskIn[0]);
  o2 = vec4(gl_PointCoord, gl_SamplePosition);
  o3 = uvec4(gl_HelperInvocation ? 1u : 0u, uint(gl_Layer), gl_ViewIndex, uint(f) + uint(np.x + ce + sa.w));
  gl_FragDepth = 0.75;
  gl_SampleMask[0] = 5;
}
