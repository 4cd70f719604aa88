#version 450
// 8- and 16-bit members of a std140 uniform block and of a push-constant block, with only the storage
// extensions (no 8/16-bit arithmetic): UniformAndStorageBuffer8BitAccess, UniformAndStorageBuffer16BitAccess,
// StoragePushConstant8 and StoragePushConstant16. Every member is widened to 32 bits and written out.
#extension GL_EXT_shader_8bit_storage : require
#extension GL_EXT_shader_16bit_storage : require
layout(local_size_x = 4) in;
layout(set = 0, binding = 0, std140) uniform U {
  int8_t s8;       // 0
  uint8_t u8;      // 1
  int16_t s16;     // 2
  uint16_t u16;    // 4
  float16_t h;     // 6
  i8vec4 v8;       // 8
  f16vec4 hv;      // 16
  u16vec2 uv;      // 24
  f16vec3 h3;      // 32
  int8_t tail;     // 38
  int16_t arr[4];  // 48, stride 16
  u8vec2 pair[2];  // 112, stride 16
} u;
layout(push_constant) uniform P {
  uint8_t u8;     // 0
  int8_t s8;      // 1
  int16_t s16;    // 2
  float16_t h;    // 4
  uint16_t u16;   // 6
  i8vec2 v8;      // 8
  f16vec2 hv;     // 12
  int8_t a8[3];   // 16, stride 1
  float16_t ha[2];  // 20, stride 2
} pc;
layout(set = 0, binding = 1, std430) writeonly buffer Out { int o[]; };
layout(set = 0, binding = 2, std430) writeonly buffer OutF { float f[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  // Dynamic indices into the arrays, one element per invocation.
  uint b = i * 24u;
  o[b + 0] = int(u.s8);
  o[b + 1] = int(u.u8);
  o[b + 2] = int(u.s16);
  o[b + 3] = int(u.u16);
  o[b + 4] = int(u.v8.x);
  o[b + 5] = int(u.v8.y);
  o[b + 6] = int(u.v8.z);
  o[b + 7] = int(u.v8.w);
  o[b + 8] = int(u.uv.x);
  o[b + 9] = int(u.uv.y);
  o[b + 10] = int(u.tail);
  o[b + 11] = int(u.arr[i % 4u]);
  o[b + 12] = int(u.pair[i % 2u].y);
  o[b + 13] = int(pc.u8);
  o[b + 14] = int(pc.s8);
  o[b + 15] = int(pc.s16);
  o[b + 16] = int(pc.u16);
  o[b + 17] = int(pc.v8.x);
  o[b + 18] = int(pc.v8.y);
  o[b + 19] = int(pc.a8[i % 3u]);
  uint c = i * 12u;
  f[c + 0] = float(u.h);
  f[c + 1] = float(u.hv.x);
  f[c + 2] = float(u.hv.y);
  f[c + 3] = float(u.hv.z);
  f[c + 4] = float(u.hv.w);
  f[c + 5] = float(u.h3.x);
  f[c + 6] = float(u.h3.y);
  f[c + 7] = float(u.h3.z);
  f[c + 8] = float(pc.h);
  f[c + 9] = float(pc.hv.x);
  f[c + 10] = float(pc.hv.y);
  f[c + 11] = float(pc.ha[i % 2u]);
}
