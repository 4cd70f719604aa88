#version 450
// Kill, terminate and demote (GraphicsShader.Discard*): mode 1 discards in a called function, 2 terminates, 3
// demotes; helper lanes' buffer writes and atomics land nowhere.
#extension GL_EXT_demote_to_helper_invocation : require
#extension GL_EXT_terminate_invocation : require
layout(location = 0) flat in int mode;
layout(location = 0, component = 1) flat in int slot;
layout(location = 0) out vec4 color;
layout(set = 0, binding = 0) buffer B { uint v[]; } buf;

void maybeDiscard() {
  if (mode == 1) discard;
}

void main() {
  color = vec4(1.0);
  maybeDiscard();
  if (mode == 2) terminateInvocation;
  if (mode == 3) demote;
  buf.v[slot] = helperInvocationEXT() ? 7u : 5u;
  atomicAdd(buf.v[8], 1u);
  color = vec4(2.0, helperInvocationEXT() ? 1.0 : 0.0, 0.0, 1.0);
}
