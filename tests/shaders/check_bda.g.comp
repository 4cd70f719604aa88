#version 460
// Device address accesses checked by VKRT_SHADER_CHECKS=bda (tests/e2e/shader_debug_test.cpp), compiled with -g:
// line 16 loads and line 17 stores through buffer_reference pointers (past the buffers where the dispatch is
// larger than they are), line 19 loads 16 bytes at `cross` (across a buffer's end), lines 22-23 load and store at
// `stray` (in no buffer at all).
#extension GL_EXT_buffer_reference : require
#extension GL_ARB_gpu_shader_int64 : require
layout(local_size_x = 8) in;
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Words { uint data[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Quad { uvec4 q; };
layout(push_constant) uniform PC { Words dst; Words src; uint64_t cross; uint64_t stray; uint mode; };
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (mode == 0u) {
    // copy: dst[i] = src[i] + 1
    uint v = src.data[i];
    dst.data[i] = v + 1u;
  } else if (i == 0u) {
    uvec4 q = Quad(cross).q;
    dst.data[0] = q.x + q.y + q.z + q.w;
    Words w = Words(stray);
    dst.data[1] = w.data[0] + 7u;
    w.data[1] = 5u;
  }
}
