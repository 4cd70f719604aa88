#version 450
// Locations and components (tests/spirv/graphics_shader_test.cpp GraphicsShader.VertexLocations): vectors, arrays,
// matrices, structs, Component decorations, 64-bit outputs, and gl_PerVertex.
#extension GL_ARB_gpu_shader_fp64 : require
layout(location = 0) in vec3 inPos;
layout(location = 1) in ivec2 inI;
layout(location = 1, component = 2) in float inC;
layout(location = 2) in mat2 inM;  // locations 2 and 3

layout(location = 0) out vec3 outArr[2];  // locations 0 and 1
layout(location = 2) flat out ivec2 outI;
layout(location = 2, component = 2) out float outC;
layout(location = 3) out mat3x2 outM;  // locations 3, 4, 5
struct S {
  float a;
  vec2 b;
};
layout(location = 6) out S outS;  // a at 6, b at 7
layout(location = 8) flat out dvec3 outD;  // x, y at 8; z at 9
out float gl_ClipDistance[2];
out float gl_CullDistance[1];

void main() {
  gl_Position = vec4(inPos * 2.0, 1.0);
  gl_PointSize = 3.0;
  gl_ClipDistance[0] = inPos.x;
  gl_ClipDistance[1] = -1.0;
  gl_CullDistance[0] = 0.25;
  outArr[0] = inPos;
  outArr[1] = inPos + vec3(10.0);
  outI = inI * 3;
  outC = inC + 0.5;
  outM = mat3x2(inM[0], inM[1], inM[0] + inM[1]);
  outS.a = inM[1].y;
  outS.b = vec2(inC, -inC);
  outD = dvec3(inPos) * 2.0lf;
}
