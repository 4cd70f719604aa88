#include "spirv/module_info.hpp"

#include <functional>
#include <map>
#include <set>
#include <unordered_map>

#include "icd/vk.hpp"

namespace vkrt::spirv {
namespace {

enum : uint32_t {
  OpEntryPoint = 15,
  OpTypeBool = 20,
  OpTypeInt = 21,
  OpTypeFloat = 22,
  OpTypeVector = 23,
  OpTypeMatrix = 24,
  OpTypeImage = 25,
  OpTypeSampler = 26,
  OpTypeSampledImage = 27,
  OpTypeArray = 28,
  OpTypeRuntimeArray = 29,
  OpTypeStruct = 30,
  OpTypePointer = 32,
  OpConstant = 43,
  OpFunction = 54,
  OpFunctionEnd = 56,
  OpFunctionCall = 57,
  OpVariable = 59,
  OpTraceRayKHR = 4445,
  OpExecuteCallableKHR = 4446,
  OpTraceNV = 5337,
  OpTraceMotionNV = 5338,
  OpTraceRayMotionNV = 5339,
  OpExecuteCallableNV = 5344,
  OpTypeAccelerationStructureKHR = 5341,
  OpTypeForwardPointer = 39,
};

bool isRayTracingStorage(uint32_t sc) {
  switch (sc) {
    case kStorageCallableData:
    case kStorageIncomingCallableData:
    case kStorageRayPayload:
    case kStorageHitAttribute:
    case kStorageIncomingRayPayload:
      return true;
    default:
      return false;
  }
}

struct FunctionInfo {
  std::set<uint32_t> callees;
  bool traces = false;
  bool callables = false;
  uint32_t localBytes = 0;
};

}  // namespace

uint32_t EntryPointInfo::bytesIn(uint32_t storageClass) const {
  uint32_t sum = 0;
  for (const InterfaceVariable& v : variables)
    if (v.storageClass == storageClass) sum += v.bytes;
  return sum;
}

uint32_t EntryPointInfo::largestIn(uint32_t storageClass) const {
  uint32_t most = 0;
  for (const InterfaceVariable& v : variables)
    if (v.storageClass == storageClass) most = std::max(most, v.bytes);
  return most;
}

uint32_t EntryPointInfo::stackSize() const {
  if (!tracesRays && !executesCallables) return 0;
  uint64_t bytes = uint64_t(bytesIn(kStorageRayPayload)) + bytesIn(kStorageCallableData) +
                   bytesIn(kStorageHitAttribute) + localBytes + kCallFrameBytes;
  bytes = (bytes + 15) / 16 * 16;
  return bytes > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(bytes);
}

const EntryPointInfo* ModuleInfo::find(const char* name, uint32_t model) const {
  for (const EntryPointInfo& e : entryPoints)
    if (e.executionModel == model && e.name == name) return &e;
  return nullptr;
}

uint32_t executionModelForStage(uint32_t vkStage) {
  switch (vkStage) {
    case VK_SHADER_STAGE_RAYGEN_BIT_KHR:
      return kModelRayGeneration;
    case VK_SHADER_STAGE_INTERSECTION_BIT_KHR:
      return kModelIntersection;
    case VK_SHADER_STAGE_ANY_HIT_BIT_KHR:
      return kModelAnyHit;
    case VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR:
      return kModelClosestHit;
    case VK_SHADER_STAGE_MISS_BIT_KHR:
      return kModelMiss;
    case VK_SHADER_STAGE_CALLABLE_BIT_KHR:
      return kModelCallable;
    default:
      return 0;
  }
}

bool analyzeModule(const uint32_t* words, size_t wordCount, ModuleInfo& out, std::string* error) {
  auto fail = [&](const char* why) {
    if (error) *error = why;
    return false;
  };
  out = {};
  if (!words || wordCount < 5 || words[0] != 0x07230203u) return fail("not a SPIR-V module (size or magic number)");
  out.version = words[1];

  struct PendingEntry {
    EntryPointInfo info;
    std::vector<uint32_t> interfaceIds;
  };
  std::vector<PendingEntry> entries;
  std::unordered_map<uint32_t, uint64_t> typeSize;      // type id -> bytes
  std::unordered_map<uint32_t, uint32_t> pointee;       // pointer type id -> pointee type id
  std::unordered_map<uint32_t, uint64_t> constants;     // constant id -> first value word(s)
  std::unordered_map<uint32_t, InterfaceVariable> globals;
  std::map<uint32_t, FunctionInfo> functions;
  FunctionInfo* current = nullptr;

  auto sizeOf = [&](uint32_t type) -> uint64_t {
    auto it = typeSize.find(type);
    return it == typeSize.end() ? 0 : it->second;
  };

  for (size_t at = 5; at < wordCount;) {
    uint32_t count = words[at] >> 16, op = words[at] & 0xffffu;
    if (count == 0 || at + count > wordCount) return fail("truncated instruction stream");
    const uint32_t* w = words + at;
    switch (op) {
      case OpEntryPoint: {
        if (count < 4) return fail("short OpEntryPoint");
        PendingEntry e;
        e.info.executionModel = w[1];
        e.info.functionId = w[2];
        size_t i = 3;
        const char* s = reinterpret_cast<const char*>(w + 3);
        size_t maxChars = (count - 3) * 4;
        size_t len = 0;
        while (len < maxChars && s[len]) ++len;
        if (len == maxChars) return fail("unterminated entry point name");
        e.info.name.assign(s, len);
        i += len / 4 + 1;
        for (; i < count; ++i) e.interfaceIds.push_back(w[i]);
        entries.push_back(std::move(e));
        break;
      }
      case OpTypeBool:
        if (count >= 2) typeSize[w[1]] = 4;
        break;
      case OpTypeInt:
      case OpTypeFloat:
        if (count >= 3) typeSize[w[1]] = w[2] / 8;
        break;
      case OpTypeVector:
      case OpTypeMatrix:
        if (count >= 4) typeSize[w[1]] = sizeOf(w[2]) * w[3];
        break;
      case OpTypeImage:
      case OpTypeSampler:
      case OpTypeSampledImage:
      case OpTypeAccelerationStructureKHR:
        if (count >= 2) typeSize[w[1]] = 8;  // a descriptor reference
        break;
      case OpTypeArray:
        if (count >= 4) {
          auto c = constants.find(w[3]);
          typeSize[w[1]] = sizeOf(w[2]) * (c == constants.end() ? 1 : c->second);
        }
        break;
      case OpTypeRuntimeArray:
        if (count >= 2) typeSize[w[1]] = 0;
        break;
      case OpTypeStruct: {
        uint64_t sum = 0;
        for (uint32_t i = 2; i < count; ++i) sum += sizeOf(w[i]);
        if (count >= 2) typeSize[w[1]] = sum;
        break;
      }
      case OpTypePointer:
        if (count >= 4) {
          typeSize[w[1]] = 8;
          pointee[w[1]] = w[3];
        }
        break;
      case OpConstant:
        if (count >= 4) constants[w[2]] = count >= 5 ? (uint64_t(w[4]) << 32 | w[3]) : w[3];
        break;
      case OpFunction:
        if (count >= 3) current = &functions[w[2]];
        break;
      case OpFunctionEnd:
        current = nullptr;
        break;
      case OpFunctionCall:
        if (current && count >= 4) current->callees.insert(w[3]);
        break;
      case OpTraceRayKHR:
      case OpTraceNV:
      case OpTraceMotionNV:
      case OpTraceRayMotionNV:
        if (current) current->traces = true;
        break;
      case OpExecuteCallableKHR:
      case OpExecuteCallableNV:
        if (current) current->callables = true;
        break;
      case OpVariable: {
        if (count < 4) break;
        auto p = pointee.find(w[1]);
        uint64_t bytes = p == pointee.end() ? 0 : sizeOf(p->second);
        uint32_t sc = w[3];
        if (current && sc == kStorageFunction) {
          current->localBytes += static_cast<uint32_t>(bytes > UINT32_MAX ? UINT32_MAX : bytes);
        } else if (!current && isRayTracingStorage(sc)) {
          globals[w[2]] = {w[2], sc, static_cast<uint32_t>(bytes > UINT32_MAX ? UINT32_MAX : bytes)};
        }
        break;
      }
      default:
        break;
    }
    at += count;
  }

  for (PendingEntry& e : entries) {
    // SPIR-V 1.4 and later list every global an entry point uses in its interface; earlier versions only
    // list Input/Output, so every ray tracing global of the module is taken.
    if (out.version >= 0x00010400u) {
      for (uint32_t id : e.interfaceIds) {
        auto g = globals.find(id);
        if (g != globals.end()) e.info.variables.push_back(g->second);
      }
    } else {
      for (auto& [id, v] : globals) e.info.variables.push_back(v);
    }
    // The call tree, breadth first (SPIR-V forbids recursion, but a visited set keeps a bad module finite).
    std::set<uint32_t> seen;
    std::vector<uint32_t> todo{e.info.functionId};
    while (!todo.empty()) {
      uint32_t f = todo.back();
      todo.pop_back();
      if (!seen.insert(f).second) continue;
      auto it = functions.find(f);
      if (it == functions.end()) continue;
      e.info.tracesRays |= it->second.traces;
      e.info.executesCallables |= it->second.callables;
      e.info.localBytes += it->second.localBytes;
      for (uint32_t c : it->second.callees) todo.push_back(c);
    }
    out.entryPoints.push_back(std::move(e.info));
  }
  return true;
}

}  // namespace vkrt::spirv
