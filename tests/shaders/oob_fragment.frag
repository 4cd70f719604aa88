#version 450
// Out-of-bounds buffer accesses of a fragment quad, per lane (GraphicsShader.*FragmentOutOfBounds*, on the fiber
// and the SPMD paths): a load and a store at an index that follows the fragment (x + 2 y: quad lane order), a store
// at a uniform index, helper lanes uncovered or demoted (a derivative makes them run).
#extension GL_EXT_demote_to_helper_invocation : require
layout(location = 0) flat in int mode;  // 2: demote
layout(location = 0) out vec4 color;
layout(set = 0, binding = 0) buffer Src { uint v[]; } src;
layout(set = 0, binding = 1) buffer Dst { uint v[]; } dst;
layout(set = 0, binding = 2) buffer Flag { uint v[]; } flag;
layout(push_constant) uniform P { uint k; } pc;
void main() {
  if (mode == 2) demote;
  uint i = uint(gl_FragCoord.x) + 2u * uint(gl_FragCoord.y);
  uint v = src.v[i];
  dst.v[i] = v + 1u;
  flag.v[pc.k] = 9u;
  color = vec4(float(v), dFdxFine(float(v)), 0.0, 0.0);  // helper lanes run: their loads count
}
