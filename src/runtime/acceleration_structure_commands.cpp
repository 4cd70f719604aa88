// The acceleration structure commands: builds (recorded, indirect, host), copies (clone, compact), serialization
// and deserialization, and property queries; recorded commands do their work when they execute, host commands
// at once or, with a VkDeferredOperationKHR, on the threads that join it.
//
// Serialized form (the header the specification defines, then vkrt's data, accel/serialize.cpp):
//   driverUUID (16) | compatibility UUID (16) | u64 serialized size | u64 deserialized size |
//   u64 N: bottom-level references | N x u64 references (device addresses of the referenced bottom-level
//   structures, which the application may patch before deserializing) | accel's serialized structure
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <functional>

#include "exec/thread_pool.hpp"
#include "runtime/acceleration_structure.hpp"
#include "runtime/acceleration_structure_build.hpp"
#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/deferred_operation.hpp"
#include "runtime/device.hpp"
#include "runtime/lookup.hpp"
#include "runtime/memory.hpp"
#include "runtime/query_pool.hpp"
#include "runtime/ray_tracing_features.hpp"
#include "runtime/report.hpp"
#include "vkrt_entrypoints.h"

namespace vkrt {

namespace {

using ull = unsigned long long;
constexpr uint64_t kHeaderBytes = 2 * VK_UUID_SIZE + 3 * 8;

// ------------------------------------------------------------------------------------------------ serialization

// The full serialized bytes of `c` (header included).
std::vector<uint8_t> serializeContent(const Device* dev, const AccelerationStructure::Content& c) {
  std::vector<uint8_t> body;
  std::vector<uint64_t> refs;
  uint64_t primitives = 0;
  if (c.tlas) {
    std::vector<const accel::Blas*> blases;  // one per instance
    body = accel::serialize(*c.tlas, &blases);
    // One reference per instance (as the CTS expects, and so that an application may give instances that shared a
    // bottom-level structure different ones): the address the instance referred to, 0 for an inactive one.
    for (size_t i = 0; i < blases.size(); ++i) refs.push_back(blases[i] ? c.blasAddresses[i] : 0);
    primitives = c.tlas->instances().size();
  } else {
    body = accel::serialize(*c.blas);
    primitives = c.blas->primitiveCount();
  }
  std::vector<uint8_t> out(kHeaderBytes + refs.size() * 8 + body.size());
  accelerationStructureVersion(dev, out.data());
  uint64_t sizes[3] = {out.size(), requiredSize(primitives), refs.size()};
  std::memcpy(out.data() + 2 * VK_UUID_SIZE, sizes, sizeof sizes);
  if (!refs.empty()) std::memcpy(out.data() + kHeaderBytes, refs.data(), refs.size() * 8);
  if (!body.empty()) std::memcpy(out.data() + kHeaderBytes + refs.size() * 8, body.data(), body.size());
  return out;
}

uint64_t serializedSize(const Device* dev, const AccelerationStructure::Content& c) {
  return serializeContent(dev, c).size();
}

// Reads serialized data at `src` (device memory unless `host`). Returns the content, or null with `error` set.
std::shared_ptr<AccelerationStructure::Content> deserializeContent(Device* dev, uint64_t src, bool host,
                                                                   std::string* error, const char** vuid) {
  *vuid = "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-src-04960";
  if (!host && !arena::accessible(src, kHeaderBytes)) {
    *error = "the serialized header is not in device memory";
    return nullptr;
  }
  const auto* p = reinterpret_cast<const uint8_t*>(src);
  uint8_t ours[2 * VK_UUID_SIZE];
  accelerationStructureVersion(dev, ours);
  if (std::memcmp(p, ours, sizeof ours) != 0) {
    *vuid = "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-pInfo-03414";
    *error =
        "the data's driver or compatibility UUID is not vkrt's (vkGetDeviceAccelerationStructureCompatibilityKHR says "
        "incompatible)";
    return nullptr;
  }
  uint64_t sizes[3];
  std::memcpy(sizes, p + 2 * VK_UUID_SIZE, sizeof sizes);
  const uint64_t total = sizes[0], count = sizes[2];
  if (total < kHeaderBytes || count > (total - kHeaderBytes) / 8 || (!host && !arena::accessible(src, total))) {
    *error = "the header's sizes are inconsistent or the data is not all in device memory";
    return nullptr;
  }
  std::vector<uint64_t> refs(count);
  if (count) std::memcpy(refs.data(), p + kHeaderBytes, count * 8);
  const uint8_t* body = p + kHeaderBytes + count * 8;
  const size_t bodyBytes = total - kHeaderBytes - count * 8;
  auto c = std::make_shared<AccelerationStructure::Content>();
  if (!accel::serializedTopLevel(body, bodyBytes)) {
    c->type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    c->blas = accel::deserializeBlas(body, bodyBytes, error);
    if (!c->blas) return nullptr;
    return c;
  }
  std::vector<std::shared_ptr<const accel::Blas>> blases(count);
  std::vector<uint64_t> at(count);
  const uint64_t generation = dev->blasGeneration.load();
  for (uint64_t i = 0; i < count; ++i) {
    if (!refs[i]) continue;
    AccelerationStructure* as = accelerationStructureAt(dev, refs[i]);
    if (!as && host) as = fromHandle<AccelerationStructure>(reinterpret_cast<VkAccelerationStructureKHR>(refs[i]));
    auto bc = as ? as->content() : nullptr;
    if (!bc || !bc->blas) {
      *error = "bottom-level reference " + std::to_string(i) + " (0x" + [&] {
        char b[32];
        std::snprintf(b, sizeof b, "%llx", (ull)refs[i]);
        return std::string(b);
      }() + ") is not a built bottom-level acceleration structure";
      return nullptr;
    }
    blases[i] = bc->blas;
    at[i] = as->address();
  }
  c->type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  c->tlas = accel::deserializeTlas(body, bodyBytes, blases, error);
  if (!c->tlas) return nullptr;
  for (size_t i = 0; i < c->tlas->instances().size(); ++i) {
    c->blasAddresses.push_back(c->tlas->instances()[i].blas && i < count ? refs[i] : 0);
    c->blasAt.push_back(c->tlas->instances()[i].blas && i < count ? at[i] : 0);
  }
  c->blasGeneration = generation;
  c->instanceCount = uint32_t(c->tlas->instances().size());
  return c;
}

// ----------------------------------------------------------------------------------------------------- queries

bool queryValue(const Device* dev, const AccelerationStructure& as, VkQueryType type, uint64_t* value,
                const char** vuid, std::string* why) {
  auto c = as.content();
  if (!c) {
    *vuid = "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964";
    *why = "was never built";
    return false;
  }
  switch (type) {
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR:
      if (!(c->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
        *vuid = "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431";
        *why = "was not built with VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR";
        return false;
      }
      [[fallthrough]];
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR:
      *value = requiredSize(c->tlas ? c->tlas->instances().size() : c->blas->primitiveCount());
      return true;
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR: *value = serializedSize(dev, *c); return true;
    case VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR:
      // The serialized header's reference count: one per instance (serializeContent).
      *value = c->tlas ? c->tlas->instances().size() : 0;
      return true;
    default:
      *vuid = "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryType-06742";
      *why = "is queried with a query type that is not an acceleration structure property";
      return false;
  }
}

// ------------------------------------------------------------------------------------------------------ helpers

bool checkScratch(const Object* about, const char* fn, uint32_t i, VkDeviceAddress scratch) {
  const uint32_t align = accelerationStructureProperties().minAccelerationStructureScratchOffsetAlignment;
  // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710
  if (scratch % align) {
    report(about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710",
           "%s: pInfos[%u].scratchData.deviceAddress 0x%llx is not a multiple of "
           "minAccelerationStructureScratchOffsetAlignment (%u)",
           fn, i, (ull)scratch, align);
    return false;
  }
  // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671 (vkrt uses none of it, but it must be there)
  if (!arena::accessible(scratch, kScratchSize)) {
    report(about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671",
           "%s: pInfos[%u].scratchData.deviceAddress 0x%llx is not %llu bytes of device memory (buildScratchSize)", fn,
           i, (ull)scratch, (ull)kScratchSize);
    return false;
  }
  return true;
}

// The checks across the infos of one command: no destination twice, no source that is another's destination. The
// infos are sorted by destination once (a command may hold a million infos: the CTS's build.*_1048576 cases), and
// each info finds its destination's next user and its source's first user by bisection; the first pair reported is
// the one a loop over (a, b) in order would find first.
bool checkDistinct(const Object* about, const char* fn, const std::vector<BuildJob>& jobs) {
  const size_t n = jobs.size();
  if (n < 2) return true;
  std::vector<std::pair<const AccelerationStructure*, size_t>> byDst(n);  // (destination, info), sorted
  for (size_t i = 0; i < n; ++i) byDst[i] = {jobs[i].dst, i};
  std::sort(byDst.begin(), byDst.end());
  std::vector<size_t> rank(n);  // info -> its place in byDst
  for (size_t r = 0; r < n; ++r) rank[byDst[r].second] = r;
  constexpr size_t kNone = SIZE_MAX;
  for (size_t a = 0; a < n; ++a) {
    // The first b > a with the same destination: the next in a's run of byDst (runs are in info order).
    const size_t r = rank[a];
    const size_t dup = r + 1 < n && byDst[r + 1].first == jobs[a].dst ? byDst[r + 1].second : kNone;
    // The first b != a whose destination is a's source (a's own destination may be its source: an update in place).
    size_t src = kNone;
    if (jobs[a].src) {
      const std::pair<const AccelerationStructure*, size_t> key{jobs[a].src, 0};
      auto it = std::lower_bound(byDst.begin(), byDst.end(), key);
      if (it != byDst.end() && it->first == jobs[a].src && it->second == a) ++it;
      if (it != byDst.end() && it->first == jobs[a].src) src = it->second;
    }
    if (dup == kNone && src == kNone) continue;
    if (dup <= src) {
      // VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698
      report(about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
             "%s: pInfos[%zu] and pInfos[%zu] build the same dstAccelerationStructure", fn, a, dup);
    } else {
      // VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403
      report(about, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403",
             "%s: pInfos[%zu].srcAccelerationStructure is pInfos[%zu].dstAccelerationStructure", fn, a, src);
    }
    return false;
  }
  return true;
}

// Runs a job and reports what its inputs broke. Returns whether it built.
bool runAndReport(const Object* about, const char* fn, const BuildJob& job) {
  BuildError e;
  if (runBuild(job.dst->device, job, &e)) return true;
  report(about, Severity::Error, e.vuid, "%s: pInfos[%u]: %s; that build is skipped", fn, job.index, e.message.c_str());
  return false;
}

// Runs the builds of one command. Its infos build distinct structures and none may read what another writes
// (VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698 to -03702: no destination overlaps another
// info's source, destination or scratch), so they run concurrently on the thread pool: a command of thousands of small
// bottom levels (one Embree scene each) keeps every core busy. Top levels go after the bottom levels of the command,
// as recorded, for an application that puts both in one command (their order is then its only synchronization).
// Returns whether every build built.
bool runJobs(const Object* about, const char* fn, const std::vector<BuildJob>& jobs) {
  std::vector<const BuildJob*> bottom, top;
  for (const BuildJob& job : jobs)
    (job.type == VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR ? top : bottom).push_back(&job);
  std::atomic<bool> ok{true};
  for (const std::vector<const BuildJob*>* group : {&bottom, &top}) {
    if (group->size() == 1) {
      ok = runAndReport(about, fn, *group->front()) && ok;
      continue;
    }
    exec::ThreadPool::instance().runConcurrently(group->size(), [&](uint64_t i) {
      if (!runAndReport(about, fn, *(*group)[i])) ok.store(false, std::memory_order_relaxed);
    });
  }
  return ok.load();
}

// Whether a host build with a deferred operation runs at once instead (vkBuildAccelerationStructuresKHR): bottom
// levels of at most kBuildNowPrimitives primitives in all (small structures: a copy of the inputs, no Embree scene),
// whose build costs less than a thread joining the operation.
constexpr uint64_t kBuildNowPrimitives = 16;
bool buildsNow(const std::vector<BuildJob>& jobs) {
  uint64_t primitives = 0;
  for (const BuildJob& job : jobs) {
    if (job.type != VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR) return false;
    for (const VkAccelerationStructureBuildRangeInfoKHR& r : job.ranges) primitives += r.primitiveCount;
  }
  return primitives <= kBuildNowPrimitives;
}

// Host commands: runs `tasks` now, or defers them to `op`'s joining threads. Returns the command's result.
VkResult runHost(Device* dev, VkDeferredOperationKHR deferred, const char* fn,
                 std::vector<std::function<bool()>> tasks) {
  if (!deferred) {
    bool ok = true;
    for (auto& t : tasks) ok &= t();
    return ok ? VK_SUCCESS : VK_ERROR_VALIDATION_FAILED_EXT;
  }
  DeferredOperation* op = fromHandle<DeferredOperation>(deferred);
  auto failed = std::make_shared<std::atomic<bool>>(false);
  std::vector<std::function<void()>> wrapped;
  for (auto& t : tasks)
    wrapped.push_back([t, failed] {
      if (!t()) failed->store(true);
    });
  // VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678
  if (!op->start(std::move(wrapped),
                 [failed] { return failed->load() ? VK_ERROR_VALIDATION_FAILED_EXT : VK_SUCCESS; })) {
    report(op, Severity::Error, "VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678",
           "%s: the deferred operation is still running a previous command", fn);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  (void)dev;
  return VK_OPERATION_DEFERRED_KHR;
}

bool checkDeferred(Device* dev, VkDeferredOperationKHR deferred, const char* fn) {
  // VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03677
  if (deferred && !fromHandle<DeferredOperation>(deferred)) {
    report(dev, Severity::Error, "VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03677",
           "%s: deferredOperation 0x%llx is not a live VkDeferredOperationKHR", fn, (ull)rawHandle(deferred));
    return false;
  }
  return true;
}

bool checkHostFeature(Device* dev, const char* fn, const char* vuid) {
  if (!dev->enabled(Feature::accelerationStructureHostCommands)) {
    report(dev, Severity::Error, vuid, "%s: the accelerationStructureHostCommands feature is not enabled", fn);
    return false;
  }
  return true;
}

// vkCmdCopyAccelerationStructureKHR / vkCopyAccelerationStructureKHR checks; returns src and dst.
bool checkCopy(Device* dev, const char* fn, const VkCopyAccelerationStructureInfoKHR& info, AccelerationStructure** src,
               AccelerationStructure** dst) {
  *src =
      liveOrReport<AccelerationStructure>(dev, info.src, fn, "VUID-VkCopyAccelerationStructureInfoKHR-src-parameter");
  *dst =
      liveOrReport<AccelerationStructure>(dev, info.dst, fn, "VUID-VkCopyAccelerationStructureInfoKHR-dst-parameter");
  if (!*src || !*dst) return false;
  // VUID-VkCopyAccelerationStructureInfoKHR-mode-03410
  if (info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR &&
      info.mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR) {
    report(dev, Severity::Error, "VUID-VkCopyAccelerationStructureInfoKHR-mode-03410",
           "%s: mode %d is neither CLONE nor COMPACT", fn, int(info.mode));
    return false;
  }
  return true;
}

// Executes a copy: the destination shares the source's (immutable) content.
bool runCopy(const Object* about, const char* fn, AccelerationStructure* src, AccelerationStructure* dst,
             VkCopyAccelerationStructureModeKHR mode) {
  auto c = src->content();
  // VUID-VkCopyAccelerationStructureInfoKHR-src-04963
  if (!c) {
    report(about, Severity::Error, "VUID-VkCopyAccelerationStructureInfoKHR-src-04963",
           "%s: the source was never built; nothing is copied", fn);
    return false;
  }
  // VUID-VkCopyAccelerationStructureInfoKHR-src-03411
  if (mode == VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR &&
      !(c->flags & VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR)) {
    report(about, Severity::Error, "VUID-VkCopyAccelerationStructureInfoKHR-src-03411",
           "%s: COMPACT copy of a structure built without VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR; "
           "nothing is copied",
           fn);
    return false;
  }
  dst->setContent(c);
  return true;
}

bool runSerialize(const Object* about, const char* fn, AccelerationStructure* src, uint64_t dst, bool host) {
  auto c = src->content();
  // VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959
  if (!c) {
    report(about, Severity::Error, "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959",
           "%s: the source was never built", fn);
    return false;
  }
  std::vector<uint8_t> bytes = serializeContent(src->device, *c);
  // VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561
  if (!host && !arena::accessible(dst, bytes.size())) {
    report(about, Severity::Error, "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561",
           "%s: the destination 0x%llx does not have the %zu bytes of the serialization size in device memory", fn,
           (ull)dst, bytes.size());
    return false;
  }
  std::memcpy(reinterpret_cast<void*>(dst), bytes.data(), bytes.size());
  return true;
}

bool runDeserialize(const Object* about, const char* fn, uint64_t src, AccelerationStructure* dst, bool host) {
  std::string error;
  const char* vuid = nullptr;
  auto c = deserializeContent(dst->device, src, host, &error, &vuid);
  if (!c) {
    report(about, Severity::Error, vuid, "%s: the serialized data at 0x%llx is refused: %s", fn, (ull)src,
           error.c_str());
    return false;
  }
  dst->setContent(std::move(c));
  return true;
}

}  // namespace

}  // namespace vkrt

using namespace vkrt;

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBuildAccelerationStructuresKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  const char* fn = "vkCmdBuildAccelerationStructuresKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdBuildAccelerationStructuresKHR-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdBuildAccelerationStructuresKHR-renderpass")) return;
  std::vector<BuildJob> jobs(infoCount);
  for (uint32_t i = 0; i < infoCount; ++i) {
    if (!makeJob(cb, fn, i, pInfos[i], ppBuildRangeInfos[i], false, &jobs[i]) ||
        !checkBuild(cb, fn, jobs[i], cb->device) || !checkScratch(cb, fn, i, pInfos[i].scratchData.deviceAddress))
      return;
  }
  if (!checkDistinct(cb, fn, jobs)) return;
  // (Moved, not copied: a command of a million infos holds a few hundred MB of them.)
  cb->record([cb, jobs = std::move(jobs)](ExecState&) { runJobs(cb, "vkCmdBuildAccelerationStructuresKHR", jobs); });
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdBuildAccelerationStructuresIndirectKHR(
    VkCommandBuffer commandBuffer, uint32_t infoCount, const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
    const VkDeviceAddress* pIndirectDeviceAddresses, const uint32_t* pIndirectStrides,
    const uint32_t* const* ppMaxPrimitiveCounts) {
  const char* fn = "vkCmdBuildAccelerationStructuresIndirectKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdBuildAccelerationStructuresIndirectKHR-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-renderpass")) return;
  // VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650
  if (!cb->device->enabled(Feature::accelerationStructureIndirectBuild)) {
    report(cb, Severity::Error,
           "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650",
           "%s: the accelerationStructureIndirectBuild feature is not enabled", fn);
    return;
  }
  struct Indirect {
    BuildJob job;
    VkDeviceAddress address;
    uint32_t stride;
    std::vector<uint32_t> maxCounts;
  };
  std::vector<Indirect> items(infoCount);
  std::vector<BuildJob> jobs(infoCount);
  for (uint32_t i = 0; i < infoCount; ++i) {
    Indirect& it = items[i];
    // Checked as a build of the maximum primitive counts (the destination's size must hold them).
    std::vector<VkAccelerationStructureBuildRangeInfoKHR> maxRanges(pInfos[i].geometryCount);
    for (uint32_t g = 0; g < pInfos[i].geometryCount; ++g) maxRanges[g].primitiveCount = ppMaxPrimitiveCounts[i][g];
    if (!makeJob(cb, fn, i, pInfos[i], maxRanges.data(), false, &it.job) || !checkBuild(cb, fn, it.job, cb->device) ||
        !checkScratch(cb, fn, i, pInfos[i].scratchData.deviceAddress))
      return;
    // VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03648, -pIndirectStrides-03787
    if (pIndirectDeviceAddresses[i] % 4 || pIndirectStrides[i] % 4) {
      report(cb, Severity::Error,
             pIndirectDeviceAddresses[i] % 4
                 ? "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03648"
                 : "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectStrides-03787",
             "%s: pIndirectDeviceAddresses[%u] 0x%llx and pIndirectStrides[%u] %u must be multiples of 4", fn, i,
             (ull)pIndirectDeviceAddresses[i], i, pIndirectStrides[i]);
      return;
    }
    it.address = pIndirectDeviceAddresses[i];
    it.stride = pIndirectStrides[i];
    it.maxCounts.assign(ppMaxPrimitiveCounts[i], ppMaxPrimitiveCounts[i] + pInfos[i].geometryCount);
    jobs[i] = it.job;
  }
  if (!checkDistinct(cb, fn, jobs)) return;
  cb->record([cb, items](ExecState&) {
    const char* fn = "vkCmdBuildAccelerationStructuresIndirectKHR";
    for (Indirect it : items) {
      const size_t n = it.job.geometries.size();
      // VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03646
      if (n && !arena::accessible(it.address,
                                  (n - 1) * uint64_t(it.stride) + sizeof(VkAccelerationStructureBuildRangeInfoKHR))) {
        report(cb, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03646",
               "%s: pInfos[%u]: the build ranges at 0x%llx are not in device memory; that build is skipped", fn,
               it.job.index, (ull)it.address);
        continue;
      }
      bool ok = true;
      for (size_t g = 0; g < n && ok; ++g) {
        std::memcpy(&it.job.ranges[g], reinterpret_cast<const void*>(it.address + g * it.stride),
                    sizeof(VkAccelerationStructureBuildRangeInfoKHR));
        // VUID-vkCmdBuildAccelerationStructuresIndirectKHR-ppMaxPrimitiveCounts-03653
        if (it.job.ranges[g].primitiveCount > it.maxCounts[g]) {
          report(cb, Severity::Error, "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-ppMaxPrimitiveCounts-03653",
                 "%s: pInfos[%u] geometry %zu: primitiveCount %u read from memory exceeds ppMaxPrimitiveCounts (%u); "
                 "that build is skipped",
                 fn, it.job.index, g, it.job.ranges[g].primitiveCount, it.maxCounts[g]);
          ok = false;
        }
      }
      if (ok) runAndReport(cb, fn, it.job);
    }
  });
}

VKAPI_ATTR VkResult VKAPI_CALL
vkrt_BuildAccelerationStructuresKHR(VkDevice device, VkDeferredOperationKHR deferredOperation, uint32_t infoCount,
                                    const VkAccelerationStructureBuildGeometryInfoKHR* pInfos,
                                    const VkAccelerationStructureBuildRangeInfoKHR* const* ppBuildRangeInfos) {
  const char* fn = "vkBuildAccelerationStructuresKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!checkHostFeature(dev, fn, "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581") ||
      !checkDeferred(dev, deferredOperation, fn))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  std::vector<BuildJob> jobs(infoCount);
  for (uint32_t i = 0; i < infoCount; ++i)
    if (!makeJob(dev, fn, i, pInfos[i], ppBuildRangeInfos[i], true, &jobs[i]) || !checkBuild(dev, fn, jobs[i], dev))
      return VK_ERROR_VALIDATION_FAILED_EXT;
  if (!checkDistinct(dev, fn, jobs)) return VK_ERROR_VALIDATION_FAILED_EXT;
  // Without a deferred operation the builds run now, concurrently (runJobs).
  if (!deferredOperation) return runJobs(dev, fn, jobs) ? VK_SUCCESS : VK_ERROR_VALIDATION_FAILED_EXT;
  // A few small bottom levels also build now, and the command returns VK_OPERATION_NOT_DEFERRED_KHR ("no operations
  // were deferred": the specification lets the implementation decide; the operation stays as it was). They take
  // microseconds, far less than joining an operation: the CTS's build.cpuht_* cases start one to eight std::threads
  // per structure to join it (a million structures in the largest), and start none for a build not deferred.
  if (buildsNow(jobs)) {
    // VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678
    if (!fromHandle<DeferredOperation>(deferredOperation)->complete()) {
      report(dev, Severity::Error, "VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678",
             "%s: the deferred operation is still running a previous command", fn);
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    return runJobs(dev, fn, jobs) ? VK_OPERATION_NOT_DEFERRED_KHR : VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // The inputs are the application's host memory, which it may change once the call returns: deferred builds read
  // them when they run, as the specification allows until the operation completes.
  std::vector<std::function<bool()>> tasks;
  for (BuildJob& job : jobs)
    tasks.push_back([dev, job] { return runAndReport(dev, "vkBuildAccelerationStructuresKHR", job); });
  return runHost(dev, deferredOperation, fn, std::move(tasks));
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyAccelerationStructureKHR(VkCommandBuffer commandBuffer,
                                                                const VkCopyAccelerationStructureInfoKHR* pInfo) {
  const char* fn = "vkCmdCopyAccelerationStructureKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdCopyAccelerationStructureKHR-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdCopyAccelerationStructureKHR-renderpass")) return;
  AccelerationStructure *src, *dst;
  if (!checkCopy(cb->device, fn, *pInfo, &src, &dst)) return;
  cb->record([cb, src, dst, mode = pInfo->mode](ExecState&) {
    runCopy(cb, "vkCmdCopyAccelerationStructureKHR", src, dst, mode);
  });
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_CopyAccelerationStructureKHR(VkDevice device,
                                                                 VkDeferredOperationKHR deferredOperation,
                                                                 const VkCopyAccelerationStructureInfoKHR* pInfo) {
  const char* fn = "vkCopyAccelerationStructureKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  AccelerationStructure *src, *dst;
  if (!checkHostFeature(dev, fn, "VUID-vkCopyAccelerationStructureKHR-accelerationStructureHostCommands-03582") ||
      !checkDeferred(dev, deferredOperation, fn) || !checkCopy(dev, fn, *pInfo, &src, &dst))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  return runHost(dev, deferredOperation, fn, {[dev, src, dst, mode = pInfo->mode] {
                   return runCopy(dev, "vkCopyAccelerationStructureKHR", src, dst, mode);
                 }});
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyAccelerationStructureToMemoryKHR(
    VkCommandBuffer commandBuffer, const VkCopyAccelerationStructureToMemoryInfoKHR* pInfo) {
  const char* fn = "vkCmdCopyAccelerationStructureToMemoryKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdCopyAccelerationStructureToMemoryKHR-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdCopyAccelerationStructureToMemoryKHR-renderpass")) return;
  auto* src = liveOrReport<AccelerationStructure>(cb, pInfo->src, fn,
                                                  "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-parameter");
  if (!src) return;
  // VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412
  if (pInfo->mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR) {
    report(cb, Severity::Error, "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412",
           "%s: mode %d is not SERIALIZE", fn, int(pInfo->mode));
    return;
  }
  // VUID-vkCmdCopyAccelerationStructureToMemoryKHR-pInfo-03740
  if (pInfo->dst.deviceAddress % 256) {
    report(cb, Severity::Error, "VUID-vkCmdCopyAccelerationStructureToMemoryKHR-pInfo-03740",
           "%s: dst.deviceAddress 0x%llx is not aligned to 256 bytes", fn, (ull)pInfo->dst.deviceAddress);
    return;
  }
  cb->record([cb, src, dst = pInfo->dst.deviceAddress](ExecState&) {
    runSerialize(cb, "vkCmdCopyAccelerationStructureToMemoryKHR", src, dst, false);
  });
}

VKAPI_ATTR VkResult VKAPI_CALL
vkrt_CopyAccelerationStructureToMemoryKHR(VkDevice device, VkDeferredOperationKHR deferredOperation,
                                          const VkCopyAccelerationStructureToMemoryInfoKHR* pInfo) {
  const char* fn = "vkCopyAccelerationStructureToMemoryKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!checkHostFeature(dev, fn,
                        "VUID-vkCopyAccelerationStructureToMemoryKHR-accelerationStructureHostCommands-03584") ||
      !checkDeferred(dev, deferredOperation, fn))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  auto* src = liveOrReport<AccelerationStructure>(dev, pInfo->src, fn,
                                                  "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-parameter");
  if (!src) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkCopyAccelerationStructureToMemoryKHR-pInfo-03751
  if (!pInfo->dst.hostAddress || reinterpret_cast<uintptr_t>(pInfo->dst.hostAddress) % 16) {
    report(dev, Severity::Error, "VUID-vkCopyAccelerationStructureToMemoryKHR-pInfo-03751",
           "%s: dst.hostAddress %p is null or not aligned to 16 bytes", fn, pInfo->dst.hostAddress);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return runHost(dev, deferredOperation, fn, {[dev, src, dst = reinterpret_cast<uint64_t>(pInfo->dst.hostAddress)] {
                   return runSerialize(dev, "vkCopyAccelerationStructureToMemoryKHR", src, dst, true);
                 }});
}

VKAPI_ATTR void VKAPI_CALL vkrt_CmdCopyMemoryToAccelerationStructureKHR(
    VkCommandBuffer commandBuffer, const VkCopyMemoryToAccelerationStructureInfoKHR* pInfo) {
  const char* fn = "vkCmdCopyMemoryToAccelerationStructureKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  // VUID-vkCmdCopyMemoryToAccelerationStructureKHR-renderpass: outside a render pass instance
  if (!cb->outsideRenderPass(fn, "VUID-vkCmdCopyMemoryToAccelerationStructureKHR-renderpass")) return;
  auto* dst = liveOrReport<AccelerationStructure>(cb, pInfo->dst, fn,
                                                  "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-dst-parameter");
  if (!dst) return;
  // VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413
  if (pInfo->mode != VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR) {
    report(cb, Severity::Error, "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413",
           "%s: mode %d is not DESERIALIZE", fn, int(pInfo->mode));
    return;
  }
  // VUID-vkCmdCopyMemoryToAccelerationStructureKHR-pInfo-03743
  if (pInfo->src.deviceAddress % 256) {
    report(cb, Severity::Error, "VUID-vkCmdCopyMemoryToAccelerationStructureKHR-pInfo-03743",
           "%s: src.deviceAddress 0x%llx is not aligned to 256 bytes", fn, (ull)pInfo->src.deviceAddress);
    return;
  }
  cb->record([cb, src = pInfo->src.deviceAddress, dst](ExecState&) {
    runDeserialize(cb, "vkCmdCopyMemoryToAccelerationStructureKHR", src, dst, false);
  });
}

VKAPI_ATTR VkResult VKAPI_CALL
vkrt_CopyMemoryToAccelerationStructureKHR(VkDevice device, VkDeferredOperationKHR deferredOperation,
                                          const VkCopyMemoryToAccelerationStructureInfoKHR* pInfo) {
  const char* fn = "vkCopyMemoryToAccelerationStructureKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!checkHostFeature(dev, fn,
                        "VUID-vkCopyMemoryToAccelerationStructureKHR-accelerationStructureHostCommands-03583") ||
      !checkDeferred(dev, deferredOperation, fn))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  auto* dst = liveOrReport<AccelerationStructure>(dev, pInfo->dst, fn,
                                                  "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-dst-parameter");
  if (!dst) return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkCopyMemoryToAccelerationStructureKHR-pInfo-03750
  if (!pInfo->src.hostAddress || reinterpret_cast<uintptr_t>(pInfo->src.hostAddress) % 16) {
    report(dev, Severity::Error, "VUID-vkCopyMemoryToAccelerationStructureKHR-pInfo-03750",
           "%s: src.hostAddress %p is null or not aligned to 16 bytes", fn, pInfo->src.hostAddress);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  return runHost(dev, deferredOperation, fn, {[dev, src = reinterpret_cast<uint64_t>(pInfo->src.hostAddress), dst] {
                   return runDeserialize(dev, "vkCopyMemoryToAccelerationStructureKHR", src, dst, true);
                 }});
}

VKAPI_ATTR void VKAPI_CALL
vkrt_CmdWriteAccelerationStructuresPropertiesKHR(VkCommandBuffer commandBuffer, uint32_t accelerationStructureCount,
                                                 const VkAccelerationStructureKHR* pAccelerationStructures,
                                                 VkQueryType queryType, VkQueryPool queryPool, uint32_t firstQuery) {
  const char* fn = "vkCmdWriteAccelerationStructuresPropertiesKHR";
  CommandBuffer* cb = CommandBuffer::recording(commandBuffer, fn);
  if (!cb) return;
  auto* pool = liveOrReport<QueryPool>(cb, queryPool, fn,
                                       "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryPool-parameter");
  if (!pool) return;
  // VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryPool-02493
  if (pool->type != queryType) {
    report(pool, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryPool-02493",
           "%s: queryType %d does not match the pool's type %d", fn, int(queryType), int(pool->type));
    return;
  }
  // VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880
  if (uint64_t(firstQuery) + accelerationStructureCount > pool->count) {
    report(pool, Severity::Error, "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880",
           "%s: firstQuery %u + %u structures exceeds the pool's %u queries", fn, firstQuery,
           accelerationStructureCount, pool->count);
    return;
  }
  std::vector<AccelerationStructure*> structures;
  for (uint32_t i = 0; i < accelerationStructureCount; ++i) {
    auto* as = liveOrReport<AccelerationStructure>(
        cb, pAccelerationStructures[i], fn,
        "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-parameter");
    if (!as) return;
    structures.push_back(as);
  }
  cb->record([cb, structures, queryType, pool, firstQuery](ExecState&) {
    for (uint32_t i = 0; i < structures.size(); ++i) {
      uint64_t v = 0;
      const char* vuid = nullptr;
      std::string why;
      if (!queryValue(cb->device, *structures[i], queryType, &v, &vuid, &why)) {
        report(cb, Severity::Error, vuid,
               "vkCmdWriteAccelerationStructuresPropertiesKHR: pAccelerationStructures[%u] %s; its query reads 0", i,
               why.c_str());
      }
      pool->writeValue(firstQuery + i, v);
    }
  });
}

VKAPI_ATTR VkResult VKAPI_CALL vkrt_WriteAccelerationStructuresPropertiesKHR(
    VkDevice device, uint32_t accelerationStructureCount, const VkAccelerationStructureKHR* pAccelerationStructures,
    VkQueryType queryType, size_t dataSize, void* pData, size_t stride) {
  const char* fn = "vkWriteAccelerationStructuresPropertiesKHR";
  Device* dev = fromHandleUnchecked<Device>(device);
  if (!checkHostFeature(dev, fn,
                        "VUID-vkWriteAccelerationStructuresPropertiesKHR-accelerationStructureHostCommands-03585"))
    return VK_ERROR_VALIDATION_FAILED_EXT;
  // VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03448 (and -03450, -06731, -06733)
  if (stride % sizeof(VkDeviceSize)) {
    report(dev, Severity::Error, "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03448",
           "%s: stride %zu is not a multiple of 8", fn, stride);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  // VUID-vkWriteAccelerationStructuresPropertiesKHR-dataSize-03452
  if (dataSize < uint64_t(accelerationStructureCount) * stride) {
    report(dev, Severity::Error, "VUID-vkWriteAccelerationStructuresPropertiesKHR-dataSize-03452",
           "%s: dataSize %zu is less than %u x stride %zu", fn, dataSize, accelerationStructureCount, stride);
    return VK_ERROR_VALIDATION_FAILED_EXT;
  }
  for (uint32_t i = 0; i < accelerationStructureCount; ++i) {
    auto* as = liveOrReport<AccelerationStructure>(
        dev, pAccelerationStructures[i], fn,
        "VUID-vkWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-parameter");
    if (!as) return VK_ERROR_VALIDATION_FAILED_EXT;
    uint64_t v = 0;
    const char* vuid = nullptr;
    std::string why;
    if (!queryValue(dev, *as, queryType, &v, &vuid, &why)) {
      report(as, Severity::Error, vuid, "%s: pAccelerationStructures[%u] %s", fn, i, why.c_str());
      return VK_ERROR_VALIDATION_FAILED_EXT;
    }
    std::memcpy(static_cast<uint8_t*>(pData) + size_t(i) * stride, &v, sizeof v);
  }
  return VK_SUCCESS;
}

}  // extern "C"
