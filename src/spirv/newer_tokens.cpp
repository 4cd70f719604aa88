#include "spirv/newer_tokens.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include <spirv/unified1/spirv.hpp>

namespace vkrt::spirv {
namespace {

constexpr size_t kHeader = 5;
constexpr const char* kExtension = "SPV_KHR_ray_tracing_position_fetch";

// Calls f(at, op, count) for each instruction; stops at a malformed one (the validator reports it).
template <typename F>
void forEach(const std::vector<uint32_t>& words, F&& f) {
  for (size_t at = kHeader; at < words.size();) {
    const uint32_t count = words[at] >> 16;
    if (count == 0 || at + count > words.size()) return;
    f(at, words[at] & 0xffff, count);
    at += count;
  }
}

bool isPositionExtension(const std::vector<uint32_t>& words, size_t at, uint32_t count) {
  const char* s = reinterpret_cast<const char*>(&words[at + 1]);
  const size_t bytes = (count - 1) * 4;
  return std::string(s, strnlen(s, bytes)) == kExtension;
}

// Where each result id is defined (type and constant declarations only).
struct Defs {
  std::unordered_map<uint32_t, size_t> at;
  const std::vector<uint32_t>& w;
  explicit Defs(const std::vector<uint32_t>& words) : w(words) {
    forEach(words, [&](size_t i, uint32_t op, uint32_t count) {
      if ((op == spv::OpTypeFloat || op == spv::OpTypeVector || op == spv::OpTypeArray || op == spv::OpTypeInt ||
           op == spv::OpTypePointer) &&
          count >= 2)
        at[w[i + 1]] = i;
      else if (op == spv::OpConstant && count >= 4)
        at[w[i + 2]] = i;
    });
  }
  const uint32_t* find(uint32_t id, uint32_t op, uint32_t minCount) const {
    auto it = at.find(id);
    if (it == at.end() || (w[it->second] & 0xffff) != op || (w[it->second] >> 16) < minCount) return nullptr;
    return &w[it->second];
  }
  // A 32-bit integer OpConstant's value, or -1.
  int64_t constant(uint32_t id) const {
    const uint32_t* c = find(id, spv::OpConstant, 4);
    if (!c) return -1;
    const uint32_t* t = find(c[1], spv::OpTypeInt, 4);
    return t && t[2] == 32 ? int64_t(c[3]) : -1;
  }
  // OpTypeArray of 3 (an integer constant) OpTypeVector of 3 OpTypeFloat 32.
  bool positionArray(uint32_t id) const {
    const uint32_t* a = find(id, spv::OpTypeArray, 4);
    if (!a || constant(a[3]) != 3) return false;
    const uint32_t* v = find(a[2], spv::OpTypeVector, 4);
    if (!v || v[3] != 3) return false;
    const uint32_t* f = find(v[2], spv::OpTypeFloat, 3);
    return f && f[2] == 32;
  }
};

}  // namespace

bool hideNewerTokensForValidation(std::vector<uint32_t>& words, std::string* error) {
  bool capTracing = false, capQuery = false, used = false;
  forEach(words, [&](size_t at, uint32_t op, uint32_t count) {
    if (op == spv::OpCapability && count >= 2) {
      capTracing |= words[at + 1] == kCapabilityRayTracingPositionFetchKHR;
      capQuery |= words[at + 1] == kCapabilityRayQueryPositionFetchKHR;
    }
    used |= op == kOpRayQueryGetIntersectionTriangleVertexPositionsKHR ||
            (op == spv::OpDecorate && count >= 4 && words[at + 2] == spv::DecorationBuiltIn &&
             words[at + 3] == kBuiltInHitTriangleVertexPositionsKHR);
  });
  if (!capTracing && !capQuery && !used) return true;
  const Defs defs(words);
  // The decorated variables, and their pointer types, checked once every OpVariable is known.
  std::vector<uint32_t> positionVariables;
  std::unordered_map<uint32_t, uint32_t> variableType;  // variable -> pointer type
  std::vector<uint32_t> out(words.begin(), words.begin() + std::min(words.size(), kHeader));
  char buf[256];
  bool ok = true;
  auto fail = [&](size_t at, const char* what) {
    if (!ok) return;
    std::snprintf(buf, sizeof buf, "at word %zu: %s", at, what);
    *error = buf;
    ok = false;
  };
  forEach(words, [&](size_t at, uint32_t op, uint32_t count) {
    if (op == spv::OpCapability && count >= 2 &&
        (words[at + 1] == kCapabilityRayTracingPositionFetchKHR ||
         words[at + 1] == kCapabilityRayQueryPositionFetchKHR))
      return;
    if (op == spv::OpExtension && isPositionExtension(words, at, count)) return;
    if (op == spv::OpDecorate && count >= 4 && words[at + 2] == spv::DecorationBuiltIn &&
        words[at + 3] == kBuiltInHitTriangleVertexPositionsKHR) {
      if (!capTracing) fail(at, "BuiltIn HitTriangleVertexPositionsKHR needs capability RayTracingPositionFetchKHR");
      positionVariables.push_back(words[at + 1]);
      return;
    }
    if (op == spv::OpVariable && count >= 4) variableType[words[at + 2]] = words[at + 1];
    if (op == kOpRayQueryGetIntersectionTriangleVertexPositionsKHR) {
      if (!capQuery)
        fail(at, "OpRayQueryGetIntersectionTriangleVertexPositionsKHR needs capability RayQueryPositionFetchKHR");
      if (count != 5) return fail(at, "OpRayQueryGetIntersectionTriangleVertexPositionsKHR has 4 operands");
      if (!defs.positionArray(words[at + 1]))
        fail(at,
             "OpRayQueryGetIntersectionTriangleVertexPositionsKHR: Result Type must be an array of 3 vec3 of "
             "32-bit floats");
      const int64_t intersection = defs.constant(words[at + 4]);
      if (intersection != 0 && intersection != 1)
        fail(at,
             "OpRayQueryGetIntersectionTriangleVertexPositionsKHR: Intersection must be a 32-bit integer "
             "constant 0 (candidate) or 1 (committed)");
      out.insert(out.end(), {(3u << 16) | spv::OpUndef, words[at + 1], words[at + 2]});
      return;
    }
    out.insert(out.end(), words.begin() + at, words.begin() + at + count);
  });
  for (uint32_t v : positionVariables) {
    auto it = variableType.find(v);
    const uint32_t* p = it == variableType.end() ? nullptr : defs.find(it->second, spv::OpTypePointer, 4);
    // VUID-HitTriangleVertexPositionsKHR-HitTriangleVertexPositionsKHR-08748 (Input) and -08749 (the type).
    if (!p || p[2] != spv::StorageClassInput || !defs.positionArray(p[3])) {
      std::snprintf(buf, sizeof buf,
                    "BuiltIn HitTriangleVertexPositionsKHR decorates %%%u, which is not an Input variable of an array "
                    "of 3 vec3 of 32-bit floats",
                    v);
      if (ok) *error = buf;
      ok = false;
    }
  }
  if (ok) words = std::move(out);
  return ok;
}

void hideNewerTokensForOptimizer(std::vector<uint32_t>& words, HiddenTokens* hidden) {
  std::vector<uint32_t> out(words.begin(), words.begin() + std::min(words.size(), kHeader));
  forEach(words, [&](size_t at, uint32_t op, uint32_t count) {
    if (op == spv::OpCapability && count >= 2 &&
        (words[at + 1] == kCapabilityRayTracingPositionFetchKHR ||
         words[at + 1] == kCapabilityRayQueryPositionFetchKHR)) {
      hidden->any = true;
      return;
    }
    if (op == spv::OpExtension && isPositionExtension(words, at, count)) {
      hidden->any = true;
      return;
    }
    const size_t start = out.size();
    out.insert(out.end(), words.begin() + at, words.begin() + at + count);
    if (op == spv::OpDecorate && count >= 4 && words[at + 2] == spv::DecorationBuiltIn &&
        words[at + 3] == kBuiltInHitTriangleVertexPositionsKHR) {
      hidden->positionVariables.push_back(words[at + 1]);
      out[start + 3] = spv::BuiltInPosition;
      hidden->any = true;
    } else if (op == kOpRayQueryGetIntersectionTriangleVertexPositionsKHR) {
      out[start] = (count << 16) | spv::OpRayQueryGetIntersectionObjectToWorldKHR;
      hidden->any = true;
    }
  });
  if (hidden->any) words = std::move(out);
}

void restoreNewerTokens(std::vector<uint32_t>& words, const HiddenTokens& hidden) {
  if (!hidden.any) return;
  std::unordered_map<uint32_t, bool> arrays;  // OpTypeArray ids
  forEach(words, [&](size_t at, uint32_t op, uint32_t count) {
    if (op == spv::OpTypeArray && count >= 2) arrays[words[at + 1]] = true;
  });
  forEach(words, [&](size_t at, uint32_t op, uint32_t count) {
    if (op == spv::OpDecorate && count >= 4 && words[at + 2] == spv::DecorationBuiltIn &&
        words[at + 3] == spv::BuiltInPosition &&
        std::find(hidden.positionVariables.begin(), hidden.positionVariables.end(), words[at + 1]) !=
            hidden.positionVariables.end())
      words[at + 3] = kBuiltInHitTriangleVertexPositionsKHR;
    else if (op == spv::OpRayQueryGetIntersectionObjectToWorldKHR && count == 5 && arrays.count(words[at + 1]))
      words[at] = (count << 16) | kOpRayQueryGetIntersectionTriangleVertexPositionsKHR;
  });
}

}  // namespace vkrt::spirv
