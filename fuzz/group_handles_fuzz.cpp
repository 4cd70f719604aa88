// libFuzzer target: shader-group handles and capture/replay data (src/rt/group_handles.cpp), the bytes an
// application hands back in shader binding tables and in VkRayTracingShaderGroupCreateInfoKHR::
// pShaderGroupCaptureReplayHandle. An input is a sequence of records, each a mode byte and 64 bytes of data, run
// against one fresh GroupRegistry and four fixed groups (general, triangles with closest hit, triangles with any
// hit and closest hit, procedural). The mode byte's bits:
//   0-1  the group the record is about
//   2    acquire the group first (as a pipeline created without capture data does)
//   3    put the group's content digest and type where capture data carries them (bytes 40..59)
//   4    make the handle part self-consistent: magic, version, type and the check value of its digest
//   5    put the right checksum in bytes 60..63
//   6    decode the two 32-byte halves as SBT handles instead of replaying
//   7    only GroupRegistry::checkCapture
// Bits 3-5 let mutations get past the checks that random bytes never pass, so that the slot table, collisions
// with acquired groups and the reservation of replayed slots are reached. Invariants checked (a violation is a
// finding): a replayed group's handle is the one the data carried; every group given out decodes to itself.
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "rt/group_handles.hpp"

namespace {

using namespace vkrt::rt;

std::shared_ptr<ShaderDesc> shader(uint32_t seed, VkShaderStageFlagBits stage) {
  auto d = std::make_shared<ShaderDesc>();
  std::vector<uint32_t> words = {0x07230203u, 0x00010000u, seed, 8, 0};
  d->codeHash = hash128(words.data(), words.size() * 4).lo;
  d->code = std::make_shared<const std::vector<uint32_t>>(std::move(words));
  d->entry = "main";
  d->stage = stage;
  if (seed & 1) d->specialization = {{0, std::string("\x01\x00\x00\x00", 4)}};
  return d;
}

const std::array<GroupDesc, 4>& groups() {
  static const std::array<GroupDesc, 4> g = [] {
    std::array<GroupDesc, 4> a;
    a[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
    a[0].shaders[kGeneral] = shader(1, VK_SHADER_STAGE_RAYGEN_BIT_KHR);
    a[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
    a[1].shaders[kClosestHit] = shader(2, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    a[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
    a[2].shaders[kClosestHit] = shader(2, VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR);
    a[2].shaders[kAnyHit] = shader(3, VK_SHADER_STAGE_ANY_HIT_BIT_KHR);
    a[3].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
    a[3].shaders[kIntersection] = shader(4, VK_SHADER_STAGE_INTERSECTION_BIT_KHR);
    return a;
  }();
  return g;
}

void put32(uint8_t* p, uint32_t v) { std::memcpy(p, &v, 4); }
void put64(uint8_t* p, uint64_t v) { std::memcpy(p, &v, 8); }
uint64_t get64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

void expect(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  GroupRegistry reg;
  std::vector<const GroupRecord*> given;
  for (size_t at = 0; at + 65 <= size; at += 65) {
    const uint8_t mode = data[at];
    uint8_t c[kCaptureSize];
    std::memcpy(c, data + at + 1, kCaptureSize);
    const GroupDesc& g = groups()[mode & 3];
    if (mode & 4) given.push_back(reg.acquire(g, nullptr));
    if (mode & 8) {
      std::string content = canonicalContent(g);
      Digest d = hash128(content.data(), content.size());
      put64(c + 40, d.lo);
      put64(c + 48, d.hi);
      put32(c + 56, uint32_t(g.type));
    }
    if (mode & 16) {
      put32(c + 4, uint32_t(get64(c + 16) >> 32));
      put32(c + 24, uint32_t(g.type) | kHandleVersion << 8);
      put32(c + 28, kHandleMagic);
      put32(c + 32, kCaptureMagic);
      put32(c + 36, kCaptureVersion);
    }
    if (mode & 32) put32(c + 60, uint32_t(hash128(c, 60).lo));
    if (mode & 128) {
      std::string content = canonicalContent(g);
      ReplayError e;
      (void)GroupRegistry::checkCapture(g, hash128(content.data(), content.size()), c, &e);
    } else if (mode & 64) {
      for (const uint8_t* h : {c, c + 32})
        if (const GroupRecord* r = reg.decode(h)) expect(std::memcmp(r->handle.data(), h, 8) == 0);
    } else {
      ReplayError e;
      if (const GroupRecord* r = reg.replay(g, c, &e)) {
        expect(std::memcmp(r->handle.data(), c, kHandleSize) == 0);
        expect(r->captureData() == r->captureData());
        given.push_back(r);
      } else {
        expect(!e.reason.empty());
      }
    }
  }
  for (const GroupRecord* r : given) expect(reg.decode(r->handle.data()) == r);
  return 0;
}
