#version 450
// Reads locations 5, 2 and 1.z (declared in that order) and takes a derivative (the quad's lanes together): slots 0,
// 1, 2 are locations 1, 2, 5, so the executor places them at the shader's locations (DrawQuadShadingTest).
layout(location = 5) in vec4 vPos;
layout(location = 2) in vec4 vColor;
layout(location = 1, component = 2) in float vScale;
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vScale * (vColor + vPos) + vec4(0.0, 0.0, 0.0, dFdx(vPos.x) * 0.0);
}
