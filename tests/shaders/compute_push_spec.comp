#version 460
// Push constants and specialization constants (including the workgroup size).
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const int kScale = 2;
layout(constant_id = 2) const bool kNegate = false;
layout(constant_id = 3) const float kBias = 0.5;
layout(push_constant) uniform Push {
  uint count;
  int offset;
  float fscale;
  vec2 extra;
} pc;
layout(set = 0, binding = 0, std430) buffer Out { float r[]; } outp;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  float v = float(int(i) * kScale + pc.offset) * pc.fscale + kBias + pc.extra.x * pc.extra.y;
  outp.r[i] = kNegate ? -v : v;
  if (i == 0u) outp.r[pc.count] = float(gl_WorkGroupSize.x);
}
