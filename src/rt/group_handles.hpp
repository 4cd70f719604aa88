// Shader-group handles and capture/replay data (docs/handles-and-capture-replay.md gives the byte layouts and why
// they are stable).
//
// A group's handle depends only on what the group does: its type and, for each of its shaders, the SPIR-V
// (the module's words), the entry point name, the stage, the stage flags and the specialization constants
// (sorted by constant id, with their bytes). That description is serialized canonically ("content"), hashed
// to a 128-bit digest, and entered in the device-wide GroupRegistry, which gives it a 32-bit slot. The
// 32-byte handle holds the slot, a check value and the digest:
//
//   bytes  0..3   slot     index into the registry's table (low 32 bits of the digest unless perturbed)
//   bytes  4..7   check    bits 32..63 of the digest's high word: verified at decode time
//   bytes  8..23  digest   the 128-bit content digest (lo, hi)
//   bytes 24..27  type     VkRayTracingShaderGroupTypeKHR | kHandleVersion << 8
//   bytes 28..31  magic    kHandleMagic ("vkRH"): a handle is never all zeros
//
// At trace time a shader binding table entry is turned into its group with GroupRegistry::decode: three
// array lookups by slot and a comparison of the check value — no hashing, no map.
//
// Collisions: if two different contents hash to the same digest, or two digests to the same slot, the later
// one is perturbed deterministically (digest / slot rehashed with an attempt counter) and an Info report
// names both. Handles of replayed groups (capture data) are reserved at the slot they carry.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "runtime/ray_tracing_features.hpp"
#include "runtime/vk.hpp"
#include "spirv/compiler.hpp"

namespace vkrt {
class Object;
class Device;
}  // namespace vkrt

namespace vkrt::rt {

constexpr uint32_t kHandleSize = kShaderGroupHandleSize;  // runtime/ray_tracing_features.hpp: what vkrt reports
constexpr uint32_t kCaptureSize = kShaderGroupCaptureReplaySize;
constexpr uint32_t kHandleMagic = 0x48526b76;   // "vkRH" little-endian
constexpr uint32_t kCaptureMagic = 0x52436b76;  // "vkCR" little-endian
constexpr uint32_t kHandleVersion = 1;
constexpr uint32_t kCaptureVersion = 1;

struct Digest {
  uint64_t lo = 0, hi = 0;
  bool operator==(const Digest&) const = default;
  auto operator<=>(const Digest&) const = default;
};

// A 128-bit hash (two multiply-xor lanes over 8-byte words, then a finalizer): stable across processes,
// runs and hosts of the same endianness.
Digest hash128(const void* data, size_t size, uint64_t seed = 0);

// One shader of a group as the application gave it, already resolved to code.
struct ShaderDesc {
  uint64_t codeHash = 0;                              // ShaderModule::contentHash (or the chained create info's)
  std::shared_ptr<const std::vector<uint32_t>> code;  // the SPIR-V, kept for trace time
  std::string entry;
  VkShaderStageFlagBits stage = VkShaderStageFlagBits(0);
  VkPipelineShaderStageCreateFlags flags = 0;
  std::vector<std::pair<uint32_t, std::string>> specialization;  // (constantID, bytes), sorted by id
  // The compiled code, shared with every pipeline and library that uses the same shader (set by the build;
  // not part of the group's content: it is derived from the fields above).
  std::shared_ptr<const spirv::CompiledShader> compiled;

  // Whether the module may read ObjectToWorldKHR / WorldToObjectKHR, and HitTriangleVertexPositionsKHR (a BuiltIn
  // decoration, or the position fetch capability, in the SPIR-V): a hit shader's invocation sets only what its
  // shader may read (exec::RayShader). Not part of the group's content (derived from `code`).
  bool readsTransforms = true;
  bool readsPositions = true;

  // vkGetRayTracingShaderGroupStackSizeKHR's figure (spirv::RayStageInfo::stackSize says how it is derived).
  uint32_t stackSize() const { return compiled ? compiled->ray.stackSize() : 0; }
};

// Which of the hit built-ins whose per-candidate set-up costs something (ShaderDesc::readsTransforms, readsPositions)
// the SPIR-V `code` may read: a BuiltIn decoration of ObjectToWorldKHR or WorldToObjectKHR; of
// HitTriangleVertexPositionsKHR, or the capability RayTracingPositionFetchKHR. Malformed code reads both.
void hitBuiltinsRead(const std::vector<uint32_t>& code, bool* transforms, bool* positions);

// Slot order within a group.
enum GroupShader : uint32_t { kGeneral = 0, kClosestHit = 1, kAnyHit = 2, kIntersection = 3 };

struct GroupDesc {
  VkRayTracingShaderGroupTypeKHR type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  std::array<std::shared_ptr<const ShaderDesc>, 4> shaders;  // null where VK_SHADER_UNUSED_KHR
};

// The canonical serialization of a group's behaviour (what the digest is taken of).
std::string canonicalContent(const GroupDesc& g);

// A group known to the device. Records live as long as the device (a handle stays decodable and
// replayable after its pipeline is destroyed).
struct GroupRecord {
  GroupDesc desc;
  std::string content;
  Digest contentDigest;  // hash128(content)
  Digest digest;         // as in the handle (== contentDigest unless perturbed)
  uint32_t slot = 0;
  bool replayed = false;
  std::array<uint8_t, kHandleSize> handle{};

  uint64_t firstPipeline = 0;  // the pipeline (handle value) the group was first created in, for reports

  uint32_t check() const { return static_cast<uint32_t>(digest.hi >> 32); }
  // The 64 bytes vkGetRayTracingCaptureReplayShaderGroupHandlesKHR writes for this group.
  std::array<uint8_t, kCaptureSize> captureData() const;
};

// Why capture data was refused.
struct ReplayError {
  std::string reason;
};

class GroupRegistry {
 public:
  GroupRegistry();
  ~GroupRegistry();

  // The record of a group created without capture data: the existing one for the same content, or a new
  // one (noting `pipeline` as the one it was first created in). `about` receives collision reports.
  // `givenAllZeroData`: the application passed capture data of all zeros, which vkrt takes as none (rt_pipeline.cpp);
  // for the CaptureReplayMixed rule the group still counts as one created with capture data.
  const GroupRecord* acquire(const GroupDesc& g, const Object* about, uint64_t pipeline = 0,
                             bool givenAllZeroData = false);
  // The record of a group created with capture data. Returns nullptr and fills `error` when the data does
  // not belong to this group (bad magic or version, corrupt, other group type, other content) or its handle
  // is taken by another group.
  const GroupRecord* replay(const GroupDesc& g, const uint8_t capture[kCaptureSize], ReplayError* error,
                            uint64_t pipeline = 0);

  // Trace-time decode: the group a handle denotes, or nullptr for a handle this device never gave out.
  // O(1): three table lookups and a check-value comparison.
  const GroupRecord* decode(const uint8_t handle[kHandleSize]) const;

  size_t size() const;
  // Whether any group was created without capture data (for the CaptureReplayMixed rule).
  bool anyNonReplayed() const { return nonReplayed_.load(); }

  // Checks capture data against a group without entering anything (used by tests and by replay).
  static bool checkCapture(const GroupDesc& g, const Digest& contentDigest, const uint8_t capture[kCaptureSize],
                           ReplayError* error);

 private:
  static constexpr uint32_t kTopBits = 12, kMidBits = 10, kLeafBits = 10;
  using Leaf = std::array<std::atomic<const GroupRecord*>, 1u << kLeafBits>;
  using Mid = std::array<std::atomic<Leaf*>, 1u << kMidBits>;

  const GroupRecord* at(uint32_t slot) const;
  void place(uint32_t slot, const GroupRecord* r);  // under mutex_
  void makeHandle(GroupRecord& r) const;

  mutable std::mutex mutex_;
  std::unique_ptr<std::atomic<Mid*>[]> top_;
  std::vector<std::unique_ptr<Leaf>> leaves_;
  std::vector<std::unique_ptr<Mid>> mids_;
  std::vector<std::unique_ptr<GroupRecord>> records_;
  std::map<Digest, const GroupRecord*> byDigest_;  // contentDigest -> first record of that content
  std::atomic<bool> nonReplayed_{false};
};

// The device's registry, created on first use.
GroupRegistry& registryOf(Device* dev);

}  // namespace vkrt::rt
