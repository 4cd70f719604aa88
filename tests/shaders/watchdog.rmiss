#version 460
#extension GL_EXT_ray_tracing : require
// tests/e2e/watchdog_test.cpp: a miss shader that loops until the payload is 0xffffffff, which never happens.
layout(location = 0) rayPayloadInEXT uint payload;
void main() {
  while (payload != 0xffffffffu) {
    payload = payload * 1664525u + 1013904223u;
    if (payload == 0xffffffffu) payload = 0u;
  }
}
