#version 450
// GL_EXT_scalar_block_layout: members aligned to their component size only. vec3 followed by a float at
// offset 12, arrays of vec3 with stride 12, a vec3 at offset 4, structs of 16 and 20 bytes; in storage
// buffers (read and written) and a uniform buffer.
#extension GL_EXT_scalar_block_layout : require
layout(local_size_x = 4) in;
struct Item {
  vec3 p;   // 0
  float w;  // 12
};
struct Odd {
  float x;  // 0
  vec3 v;   // 4
  int k;    // 16 (size 20)
};
layout(set = 0, binding = 0, scalar) readonly buffer In {
  vec3 a;         // 0
  float b;        // 12
  vec3 arr[8];    // 16, stride 12
  float c;        // 112
  vec2 v2;        // 116
  Item items[3];  // 124, stride 16
  Odd odd[];      // 172, stride 20
} inp;
layout(set = 0, binding = 1, scalar) uniform U {
  float s;    // 0
  vec3 off;   // 4
  vec2 k;     // 16
  vec3 m[2];  // 24, stride 12
} u;
layout(set = 0, binding = 2, scalar) writeonly buffer Out {
  vec3 r[8];    // 0, stride 12
  float tail;   // 96
  Odd o[];      // 100, stride 20
} outp;

void main() {
  uint i = gl_GlobalInvocationID.x;
  vec3 x = inp.arr[i] * u.s + u.off;
  outp.r[i] = x + vec3(inp.b, inp.c, inp.items[i % 3u].w) + u.m[i % 2u];
  Odd d = inp.odd[i];
  d.x += inp.a.x + inp.v2.y;
  d.v = d.v * u.k.x + inp.items[i % 3u].p;
  d.k = d.k * 2 + int(i);
  outp.o[i] = d;
  if (i == 0u) outp.tail = inp.a.y + inp.a.z + inp.v2.x + u.k.y;
}
