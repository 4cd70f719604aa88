#version 460
// Loops (for, while, do-while, break, continue), switch, nested ifs and function calls.
layout(local_size_x = 8) in;
layout(set = 0, binding = 0, std430) buffer Data { uint v[]; } data;

uint collatzSteps(uint n) {
  uint steps = 0u;
  while (n != 1u && steps < 1000u) {
    n = (n % 2u == 0u) ? n / 2u : 3u * n + 1u;
    steps++;
  }
  return steps;
}

uint classify(uint n) {
  switch (n % 6u) {
    case 0u: return 10u;
    case 1u:
    case 2u: return 20u + n;
    case 4u: break;
    default: return 30u;
  }
  return 40u;
}

uint sumSkipping(uint n) {
  uint s = 0u;
  for (uint k = 0u; k < n; ++k) {
    if (k % 3u == 0u) continue;
    if (k > 50u) break;
    s += k;
  }
  uint j = 0u;
  do { s += j; j += 2u; } while (j < n);
  return s;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint n = data.v[i];
  data.v[i] = collatzSteps(n + 1u) * 1000000u + classify(n) * 1000u + sumSkipping(n);
}
