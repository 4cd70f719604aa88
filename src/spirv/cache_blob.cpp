// The pipeline cache form of a compiled shader (cache_blob.hpp): the key a compile request is cached under and the
// blob a compiled shader is stored as (VkPipelineCache, CompiledShader::cacheBlob).
#include "spirv/cache_blob.hpp"

#include <llvm/Config/llvm-config.h>
#include <llvm/Support/SHA256.h>

#include <link.h>

#include <algorithm>
#include <cstring>

#include "abi/abi.hpp"
#include "spirv/shader_debug.hpp"
#include "spirv/spmd.hpp"
#include "spirv/target.hpp"

namespace vkrt::spirv {

// The blob:
//
//   char magic[8] "VKRTSHD9"; uint8 sha256[32] of the payload; payload:
//   u32 localSize[3], workgroupMemorySize, usesBarrier, hasGroupEntry | spmdLanes << 8, pushConstantBytes, model;
//   u32 ray.payloadBytes, callableDataBytes, hitAttributeBytes, frameBytes, callsOut | readsHitAttributes << 1 |
//   checksPendingAdds << 2;
//   graphics: u32 flags (the GraphicsStageInfo booleans, bit by bit in declaration order), clipDistances,
//   cullDistances; u32 n + n x 8 bytes (inputs), u32 n + n x 8 bytes (outputs): {location, componentMask,
//   interpolation, centroid | sample << 1 | integer << 2 | wide << 3, 4 zero bytes};
//   u32 n + entry name; u32 n + n x {u32 set, binding, arraySize, uniform | kind << 1}; the rest: the object file.
// Every field of CompiledShader that describes the code must be here: a new one needs a line in
// serialize() and deserialize() (the size check below is the reminder).
static_assert(sizeof(CompiledShader) == 264,
              "serialize the new CompiledShader field for VkPipelineCache, then update this size");

// 6: shader record reads call RayRuntime::shaderRecordOutsideRegion, which an older vkrt does not provide. 8: the
// graphics flags readsFragCoord, readsPointCoord and readsSampleMask (7 had the first alone), which an older blob
// lacks: read as false, they would leave those built-ins unset. 9: SPMD storage image accesses read an image view
// record's address as its abi::ImageTexels, which an older vkrt's records do not hold.
constexpr char kBlobMagic[8] = {'V', 'K', 'R', 'T', 'S', 'H', 'D', '9'};

namespace {

void put32(std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

struct Reader {
  std::string_view rest;
  bool ok = true;
  uint32_t u32() {
    if (rest.size() < 4) {
      ok = false;
      return 0;
    }
    uint32_t v;
    std::memcpy(&v, rest.data(), 4);
    rest.remove_prefix(4);
    return v;
  }
  std::string_view bytes(uint32_t n) {
    if (rest.size() < n) {
      ok = false;
      return {};
    }
    std::string_view v = rest.substr(0, n);
    rest.remove_prefix(n);
    return v;
  }
};

// The build id of the binary vkrt's code is in (a rebuilt vkrt may generate different code).
std::string buildId() {
  static const std::string id = [] {
    struct Search {
      uintptr_t address;
      std::string id;
    } search{reinterpret_cast<uintptr_t>(&buildId), {}};
    dl_iterate_phdr(
        [](dl_phdr_info* info, size_t, void* data) -> int {
          auto* s = static_cast<Search*>(data);
          bool mine = false;
          for (int i = 0; i < info->dlpi_phnum && !mine; ++i) {
            const ElfW(Phdr)& ph = info->dlpi_phdr[i];
            uintptr_t start = info->dlpi_addr + ph.p_vaddr;
            mine = ph.p_type == PT_LOAD && s->address >= start && s->address < start + ph.p_memsz;
          }
          if (!mine) return 0;
          for (int i = 0; i < info->dlpi_phnum; ++i) {
            const ElfW(Phdr)& ph = info->dlpi_phdr[i];
            if (ph.p_type != PT_NOTE) continue;
            auto* p = reinterpret_cast<const uint8_t*>(info->dlpi_addr + ph.p_vaddr);
            size_t at = 0;
            while (at + sizeof(ElfW(Nhdr)) <= ph.p_memsz) {
              auto* n = reinterpret_cast<const ElfW(Nhdr)*>(p + at);
              size_t name = at + sizeof(ElfW(Nhdr)), desc = name + ((n->n_namesz + 3) & ~3u);
              if (n->n_type == NT_GNU_BUILD_ID && n->n_namesz == 4 && std::memcmp(p + name, "GNU", 4) == 0)
                s->id.assign(reinterpret_cast<const char*>(p + desc), n->n_descsz);
              at = desc + ((n->n_descsz + 3) & ~3u);
            }
          }
          return 1;
        },
        &search);
    // Without a build id, the time this file was compiled stands in.
    return search.id.empty() ? std::string(__DATE__ " " __TIME__) : search.id;
  }();
  return id;
}

}  // namespace

std::string serialize(const CompiledShader& s, std::string_view object) {
  std::string payload;
  for (uint32_t v : s.localSize) put32(payload, v);
  put32(payload, s.workgroupMemorySize);
  put32(payload, s.usesBarrier ? 1 : 0);
  // hasGroupEntry (a fragment shader's vkrt_group is its graphicsEntry, spmdLanes 4; a ray generation shader's its
  // rayBatchEntry beside vkrt_main), SPMD lanes
  put32(payload, s.groupEntry || s.spmdLanes ? 1u | uint32_t(s.spmdLanes) << 8 : 0);
  put32(payload, s.pushConstantBytes);
  put32(payload, uint32_t(s.model));
  for (uint32_t v : {s.ray.payloadBytes, s.ray.callableDataBytes, s.ray.hitAttributeBytes, s.ray.frameBytes})
    put32(payload, v);
  put32(payload,
        (s.ray.callsOut ? 1u : 0u) | (s.ray.readsHitAttributes ? 2u : 0u) | (s.ray.checksPendingAdds ? 4u : 0u));
  const GraphicsStageInfo& g = s.graphics;
  uint32_t flags = 0, bit = 0;
  for (bool f : {g.needsQuad, g.writesDepth, g.writesSampleMask, g.readsSampleId, g.canDiscard, g.earlyFragmentTests,
                 g.sideEffects, g.dualSource, g.writesPointSize, g.readsFragCoord, g.readsPointCoord, g.readsSampleMask,
                 g.mergesColor})
    flags |= uint32_t(f) << bit++;
  put32(payload, flags);
  put32(payload, g.clipDistances);
  put32(payload, g.cullDistances);
  for (const auto* list : {&g.inputs, &g.outputs}) {
    put32(payload, uint32_t(list->size()));
    for (const GraphicsStageInfo::Location& l : *list) {
      put32(payload, l.location | uint32_t(l.componentMask) << 8 | uint32_t(l.interpolation) << 16 |
                         uint32_t(l.centroid | l.sample << 1 | l.integer << 2 | l.wide << 3) << 24);
      put32(payload, 0);
    }
  }
  put32(payload, uint32_t(s.entryName.size()));
  payload += s.entryName;
  put32(payload, uint32_t(s.resources.size()));
  for (const ResourceBinding& r : s.resources) {
    put32(payload, r.set);
    put32(payload, r.binding);
    put32(payload, r.arraySize);
    put32(payload, (r.uniform ? 1u : 0u) | uint32_t(r.kind) << 1);  // bit 0: uniform; bits 1+: kind
  }
  payload.append(object.data(), object.size());
  auto digest =
      llvm::SHA256::hash(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(payload.data()), payload.size()));
  std::string blob(kBlobMagic, sizeof kBlobMagic);
  blob.append(reinterpret_cast<const char*>(digest.data()), digest.size());
  return blob + payload;
}

// Fills `s` from a blob's fields; returns the object file, or nullopt when the blob is damaged.
std::optional<std::string_view> deserialize(std::string_view blob, CompiledShader& s, bool* hasGroupEntry) {
  if (blob.size() < 40 || std::memcmp(blob.data(), kBlobMagic, 8) != 0) return std::nullopt;
  std::string_view payload = blob.substr(40);
  auto digest =
      llvm::SHA256::hash(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(payload.data()), payload.size()));
  if (std::memcmp(digest.data(), blob.data() + 8, 32) != 0) return std::nullopt;
  Reader r{payload};
  for (uint32_t& v : s.localSize) v = r.u32();
  s.workgroupMemorySize = r.u32();
  s.usesBarrier = r.u32() != 0;
  uint32_t group = r.u32();
  *hasGroupEntry = (group & 1) != 0;
  s.spmdLanes = uint8_t(group >> 8);
  s.pushConstantBytes = r.u32();
  s.model = spv::ExecutionModel(r.u32());
  s.ray.payloadBytes = r.u32();
  s.ray.callableDataBytes = r.u32();
  s.ray.hitAttributeBytes = r.u32();
  s.ray.frameBytes = r.u32();
  uint32_t rayFlags = r.u32();
  s.ray.callsOut = (rayFlags & 1) != 0;
  s.ray.checksPendingAdds = (rayFlags & 4) != 0;
  s.ray.readsHitAttributes = (rayFlags & 2) != 0;
  GraphicsStageInfo& g = s.graphics;
  uint32_t flags = r.u32(), bit = 0;
  for (bool* f : {&g.needsQuad, &g.writesDepth, &g.writesSampleMask, &g.readsSampleId, &g.canDiscard,
                  &g.earlyFragmentTests, &g.sideEffects, &g.dualSource, &g.writesPointSize, &g.readsFragCoord,
                  &g.readsPointCoord, &g.readsSampleMask, &g.mergesColor})
    *f = (flags >> bit++ & 1) != 0;
  g.clipDistances = r.u32();
  g.cullDistances = r.u32();
  for (auto* list : {&g.inputs, &g.outputs}) {
    uint32_t n = r.u32();
    if (!r.ok || n > abi::kGraphicsLocations) return std::nullopt;
    for (uint32_t i = 0; i < n; ++i) {
      uint32_t w = r.u32();
      r.u32();
      GraphicsStageInfo::Location l;
      l.location = uint8_t(w);
      l.componentMask = uint8_t(w >> 8);
      l.interpolation = GraphicsStageInfo::Location::Interpolation(std::min<uint32_t>(w >> 16 & 0xff, 2));
      uint32_t b = w >> 24;
      l.centroid = b & 1;
      l.sample = b & 2;
      l.integer = b & 4;
      l.wide = b & 8;
      list->push_back(l);
    }
  }
  uint32_t nameSize = r.u32();
  s.entryName = std::string(r.bytes(nameSize));
  uint32_t count = r.u32();
  if (!r.ok || count > r.rest.size() / 16) return std::nullopt;
  for (uint32_t i = 0; i < count; ++i) {
    ResourceBinding b{};
    b.set = r.u32();
    b.binding = r.u32();
    b.arraySize = r.u32();
    uint32_t flags = r.u32();
    b.uniform = (flags & 1) != 0;
    b.kind = ResourceBinding::Kind(std::min<uint32_t>(flags >> 1, ResourceBinding::InputAttachment));  // the last
    s.resources.push_back(b);
  }
  if (!r.ok || r.rest.empty()) return std::nullopt;
  return r.rest;
}

std::string cacheKey(const CompileRequest& req) {
  llvm::SHA256 h;
  auto add = [&](const void* data, size_t size) {
    uint64_t n = size;
    h.update(llvm::ArrayRef<uint8_t>(reinterpret_cast<const uint8_t*>(&n), sizeof n));
    h.update(llvm::ArrayRef<uint8_t>(static_cast<const uint8_t*>(data), size));
  };
  auto addStr = [&](const std::string& s) { add(s.data(), s.size()); };
  addStr("vkrt compiled shader 4");
  addStr(LLVM_VERSION_STRING);
  addStr(buildId());
  addStr(detail::targetKey());
  addStr(spmdKey());
  addStr("checks " + std::to_string(shaderChecks()));  // VKRT_SHADER_CHECKS: compiled in or not
  add(req.words, req.wordCount * sizeof(uint32_t));
  addStr(req.entryName);
  uint32_t model = req.model, inl = req.inlineFunctions, adds = req.combineAdds;
  add(&model, 4);
  add(&inl, 4);
  add(&adds, 4);
  if (req.colorMerge.format != abi::ColorMerge::kNone) {  // (absent: the key of a shader compiled before it existed)
    const uint8_t merge[3] = {uint8_t(req.colorMerge.format), uint8_t(req.colorMerge.blend), req.colorMerge.writeMask};
    add(merge, sizeof merge);
  }
  for (const SpecValue& v : req.specialization) {
    add(&v.specId, sizeof v.specId);
    add(v.bytes.data(), v.bytes.size());
  }
  auto digest = h.final();
  return std::string("vkrt-shader:") + std::string(reinterpret_cast<const char*>(digest.data()), digest.size());
}

}  // namespace vkrt::spirv
