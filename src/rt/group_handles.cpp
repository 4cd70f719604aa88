#include "rt/group_handles.hpp"

#include <algorithm>
#include <cstring>

#include "runtime/device.hpp"
#include "runtime/report.hpp"

namespace vkrt::rt {
namespace {

uint64_t fmix(uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdull;
  k ^= k >> 33;
  k *= 0xc4ceb9fe1a85ec53ull;
  k ^= k >> 33;
  return k;
}

uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

void put32(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
void put64(uint8_t* p, uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
uint32_t get32(const uint8_t* p) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= uint32_t(p[i]) << (8 * i);
  return v;
}
uint64_t get64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= uint64_t(p[i]) << (8 * i);
  return v;
}

void append32(std::string& s, uint32_t v) {
  uint8_t b[4];
  put32(b, v);
  s.append(reinterpret_cast<char*>(b), 4);
}
void append64(std::string& s, uint64_t v) {
  uint8_t b[8];
  put64(b, v);
  s.append(reinterpret_cast<char*>(b), 8);
}
void appendString(std::string& s, const std::string& v) {
  append32(s, static_cast<uint32_t>(v.size()));
  s += v;
}

// A perturbed value for attempt n (n >= 1): deterministic, so the same creation order gives the same result.
uint32_t perturbSlot(const Digest& d, uint32_t attempt) {
  return static_cast<uint32_t>(fmix(d.lo ^ rotl(d.hi, 17) ^ (0x9e3779b97f4a7c15ull * attempt)));
}

// Takes the type as a 32-bit word: capture data from the application may carry any value there, and one past
// the enum's range (0x7fffffff) does not fit VkRayTracingShaderGroupTypeKHR.
const char* typeName(uint32_t t) {
  switch (t) {
    case VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR: return "GENERAL";
    case VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR: return "TRIANGLES_HIT_GROUP";
    case VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR: return "PROCEDURAL_HIT_GROUP";
    default: return "unknown";
  }
}

}  // namespace

// SPIR-V tokens the scan below reads (the SPIR-V specification's numbers; the NV ray tracing built-ins share them).
constexpr uint32_t kOpCapability = 17, kOpDecorate = 71, kOpMemberDecorate = 72, kDecorationBuiltIn = 11;
constexpr uint32_t kBuiltInObjectToWorld = 5330, kBuiltInWorldToObject = 5331,
                   kBuiltInHitTriangleVertexPositions = 5335;
constexpr uint32_t kCapabilityRayTracingPositionFetch = 5336;

void hitBuiltinsRead(const std::vector<uint32_t>& code, bool* transforms, bool* positions) {
  *transforms = *positions = false;
  for (size_t at = 5; at < code.size();) {
    const uint32_t count = code[at] >> 16, op = code[at] & 0xFFFF;
    if (count == 0 || at + count > code.size()) {  // malformed (validation refused it already): assume both
      *transforms = *positions = true;
      return;
    }
    if (op == kOpCapability && count >= 2 && code[at + 1] == kCapabilityRayTracingPositionFetch) *positions = true;
    const bool decorate = op == kOpDecorate && count >= 4;
    const bool memberDecorate = op == kOpMemberDecorate && count >= 5;
    if ((decorate || memberDecorate) && code[at + (decorate ? 2 : 3)] == kDecorationBuiltIn) {
      const uint32_t builtIn = code[at + (decorate ? 3 : 4)];
      if (builtIn == kBuiltInObjectToWorld || builtIn == kBuiltInWorldToObject) *transforms = true;
      if (builtIn == kBuiltInHitTriangleVertexPositions) *positions = true;
    }
    at += count;
  }
}

Digest hash128(const void* data, size_t size, uint64_t seed) {
  const auto* p = static_cast<const uint8_t*>(data);
  uint64_t h1 = seed ^ 0x6a09e667f3bcc908ull, h2 = seed ^ 0xbb67ae8584caa73bull;
  const uint64_t c1 = 0x87c37b91114253d5ull, c2 = 0x4cf5ad432745937full;
  size_t i = 0;
  for (; i + 16 <= size; i += 16) {
    uint64_t k1 = get64(p + i), k2 = get64(p + i + 8);
    h1 ^= rotl(k1 * c1, 31) * c2;
    h1 = rotl(h1, 27) + h2;
    h1 = h1 * 5 + 0x52dce729;
    h2 ^= rotl(k2 * c2, 33) * c1;
    h2 = rotl(h2, 31) + h1;
    h2 = h2 * 5 + 0x38495ab5;
  }
  uint8_t tail[16] = {};
  std::memcpy(tail, p + i, size - i);
  h1 ^= rotl(get64(tail) * c1, 31) * c2;
  h2 ^= rotl(get64(tail + 8) * c2, 33) * c1;
  h1 ^= size;
  h2 ^= size;
  h1 += h2;
  h2 += h1;
  h1 = fmix(h1);
  h2 = fmix(h2);
  h1 += h2;
  h2 += h1;
  return {h1, h2};
}

std::string canonicalContent(const GroupDesc& g) {
  std::string s = "vkrt-group-v1";
  append32(s, static_cast<uint32_t>(g.type));
  for (uint32_t i = 0; i < 4; ++i) {
    const ShaderDesc* sh = g.shaders[i].get();
    append32(s, sh ? 1 : 0);
    if (!sh) continue;
    append64(s, sh->codeHash);
    append32(s, sh->code ? static_cast<uint32_t>(sh->code->size()) : 0);
    appendString(s, sh->entry);
    append32(s, static_cast<uint32_t>(sh->stage));
    append32(s, sh->flags);
    append32(s, static_cast<uint32_t>(sh->specialization.size()));
    for (auto& [id, bytes] : sh->specialization) {
      append32(s, id);
      appendString(s, bytes);
    }
  }
  return s;
}

std::array<uint8_t, kCaptureSize> GroupRecord::captureData() const {
  std::array<uint8_t, kCaptureSize> c{};
  std::memcpy(c.data(), handle.data(), kHandleSize);
  put32(c.data() + 32, kCaptureMagic);
  put32(c.data() + 36, kCaptureVersion);
  put64(c.data() + 40, contentDigest.lo);
  put64(c.data() + 48, contentDigest.hi);
  put32(c.data() + 56, static_cast<uint32_t>(desc.type));
  put32(c.data() + 60, static_cast<uint32_t>(hash128(c.data(), 60).lo));
  return c;
}

GroupRegistry::GroupRegistry() : top_(new std::atomic<Mid*>[1u << kTopBits]) {
  for (uint32_t i = 0; i < (1u << kTopBits); ++i) top_[i].store(nullptr);
}

GroupRegistry::~GroupRegistry() = default;

const GroupRecord* GroupRegistry::at(uint32_t slot) const {
  Mid* mid = top_[slot >> (kMidBits + kLeafBits)].load(std::memory_order_acquire);
  if (!mid) return nullptr;
  Leaf* leaf = (*mid)[(slot >> kLeafBits) & ((1u << kMidBits) - 1)].load(std::memory_order_acquire);
  if (!leaf) return nullptr;
  return (*leaf)[slot & ((1u << kLeafBits) - 1)].load(std::memory_order_acquire);
}

void GroupRegistry::place(uint32_t slot, const GroupRecord* r) {
  auto& topEntry = top_[slot >> (kMidBits + kLeafBits)];
  Mid* mid = topEntry.load();
  if (!mid) {
    mids_.push_back(std::make_unique<Mid>());
    mid = mids_.back().get();
    for (auto& e : *mid) e.store(nullptr);
    topEntry.store(mid, std::memory_order_release);
  }
  auto& midEntry = (*mid)[(slot >> kLeafBits) & ((1u << kMidBits) - 1)];
  Leaf* leaf = midEntry.load();
  if (!leaf) {
    leaves_.push_back(std::make_unique<Leaf>());
    leaf = leaves_.back().get();
    for (auto& e : *leaf) e.store(nullptr);
    midEntry.store(leaf, std::memory_order_release);
  }
  (*leaf)[slot & ((1u << kLeafBits) - 1)].store(r, std::memory_order_release);
}

void GroupRegistry::makeHandle(GroupRecord& r) const {
  uint8_t* h = r.handle.data();
  put32(h + 0, r.slot);
  put32(h + 4, r.check());
  put64(h + 8, r.digest.lo);
  put64(h + 16, r.digest.hi);
  put32(h + 24, static_cast<uint32_t>(r.desc.type) | kHandleVersion << 8);
  put32(h + 28, kHandleMagic);
}

const GroupRecord* GroupRegistry::acquire(const GroupDesc& g, const Object* about, uint64_t pipeline,
                                          bool givenAllZeroData) {
  if (!givenAllZeroData) nonReplayed_.store(true);
  auto rec = std::make_unique<GroupRecord>();
  rec->firstPipeline = pipeline;
  rec->desc = g;
  rec->content = canonicalContent(g);
  rec->contentDigest = hash128(rec->content.data(), rec->content.size());
  rec->digest = rec->contentDigest;
  std::lock_guard lock(mutex_);
  auto it = byDigest_.find(rec->contentDigest);
  if (it != byDigest_.end()) {
    if (it->second->content == rec->content) return it->second;
    // Two contents, one digest: perturb this one's digest until it is unique.
    for (uint32_t attempt = 1;; ++attempt) {
      Digest d = hash128(&rec->contentDigest, sizeof(Digest), attempt);
      bool taken = false;
      for (auto& r : records_) taken |= r->digest == d;
      if (!taken) {
        report(about, Severity::Info, nullptr,
               "shader group handles: content digest %016llx%016llx of a %s group collides with another group's; "
               "this group's handle digest is perturbed (attempt %u)",
               (unsigned long long)rec->contentDigest.hi, (unsigned long long)rec->contentDigest.lo, typeName(g.type),
               attempt);
        rec->digest = d;
        break;
      }
    }
  }
  rec->slot = static_cast<uint32_t>(rec->digest.lo);
  for (uint32_t attempt = 1; at(rec->slot); ++attempt) {
    uint32_t next = perturbSlot(rec->digest, attempt);
    report(about, Severity::Info, nullptr,
           "shader group handles: slot %u of a %s group is taken by another group; moved to slot %u", rec->slot,
           typeName(g.type), next);
    rec->slot = next;
  }
  makeHandle(*rec);
  place(rec->slot, rec.get());
  if (it == byDigest_.end()) byDigest_[rec->contentDigest] = rec.get();
  records_.push_back(std::move(rec));
  return records_.back().get();
}

bool GroupRegistry::checkCapture(const GroupDesc& g, const Digest& contentDigest, const uint8_t* c,
                                 ReplayError* error) {
  auto fail = [&](std::string why) {
    if (error) error->reason = std::move(why);
    return false;
  };
  char buf[256];
  if (get32(c + 32) != kCaptureMagic || get32(c + 36) != kCaptureVersion) {
    std::snprintf(buf, sizeof(buf),
                  "not vkrt capture data of version %u (magic 0x%08x, expected 0x%08x; version %u): truncated or "
                  "from another driver",
                  kCaptureVersion, get32(c + 32), kCaptureMagic, get32(c + 36));
    return fail(buf);
  }
  uint32_t sum = static_cast<uint32_t>(hash128(c, 60).lo);
  if (get32(c + 60) != sum) {
    std::snprintf(buf, sizeof(buf), "corrupt capture data: checksum 0x%08x, the bytes give 0x%08x", get32(c + 60), sum);
    return fail(buf);
  }
  if (get32(c + 28) != kHandleMagic || (get32(c + 24) >> 8) != kHandleVersion)
    return fail("corrupt capture data: the handle it carries is not a vkrt handle");
  if (get32(c + 56) != static_cast<uint32_t>(g.type)) {
    std::snprintf(buf, sizeof(buf), "captured from a %s group, given to a %s group", typeName(get32(c + 56)),
                  typeName(g.type));
    return fail(buf);
  }
  Digest captured{get64(c + 40), get64(c + 48)};
  if (!(captured == contentDigest)) {
    std::snprintf(buf, sizeof(buf),
                  "captured from a group with other shaders (content digest %016llx%016llx; this group's is "
                  "%016llx%016llx): different SPIR-V, entry point, stage flags or specialization",
                  (unsigned long long)captured.hi, (unsigned long long)captured.lo,
                  (unsigned long long)contentDigest.hi, (unsigned long long)contentDigest.lo);
    return fail(buf);
  }
  return true;
}

const GroupRecord* GroupRegistry::replay(const GroupDesc& g, const uint8_t* c, ReplayError* error, uint64_t pipeline) {
  auto rec = std::make_unique<GroupRecord>();
  rec->firstPipeline = pipeline;
  rec->desc = g;
  rec->content = canonicalContent(g);
  rec->contentDigest = hash128(rec->content.data(), rec->content.size());
  if (!checkCapture(g, rec->contentDigest, c, error)) return nullptr;
  rec->slot = get32(c + 0);
  rec->digest = {get64(c + 8), get64(c + 16)};
  rec->replayed = true;
  makeHandle(*rec);
  if (std::memcmp(rec->handle.data(), c, kHandleSize) != 0) {
    if (error) error->reason = "corrupt capture data: the handle's check value does not match its digest";
    return nullptr;
  }
  std::lock_guard lock(mutex_);
  if (const GroupRecord* existing = at(rec->slot)) {
    if (existing->content == rec->content && existing->handle == rec->handle) return existing;
    char buf[200];
    std::snprintf(buf, sizeof(buf),
                  "the captured handle (slot %u) is already held by a different %s group on this device", rec->slot,
                  typeName(existing->desc.type));
    if (error) error->reason = buf;
    return nullptr;
  }
  // Reserved: acquire() never hands this slot out to another content.
  place(rec->slot, rec.get());
  byDigest_.emplace(rec->contentDigest, rec.get());
  records_.push_back(std::move(rec));
  return records_.back().get();
}

const GroupRecord* GroupRegistry::decode(const uint8_t* h) const {
  if (get32(h + 28) != kHandleMagic) return nullptr;
  const GroupRecord* r = at(get32(h + 0));
  if (!r || r->check() != get32(h + 4)) return nullptr;
  return r;
}

size_t GroupRegistry::size() const {
  std::lock_guard lock(mutex_);
  return records_.size();
}

GroupRegistry& registryOf(Device* dev) {
  std::call_once(dev->groupRegistryOnce, [&] { dev->groupRegistry = std::make_shared<GroupRegistry>(); });
  return *dev->groupRegistry;
}

}  // namespace vkrt::rt
