#include "exec/ray_tree.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <utility>

#include "exec/ray_query.hpp"

namespace vkrt::exec {

// ------------------------------------------------------------------------------------------------ the setting

namespace {

// Reads up to three comma-separated decimal numbers (at least `minCount`) of one entry; spaces around them.
bool parseId(std::string_view s, size_t minCount, RayTreeId* id, std::string* error) {
  *id = {0, 0, 0};
  size_t count = 0, i = 0;
  auto skipSpaces = [&] {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  };
  for (;;) {
    skipSpaces();
    if (count == 3) {
      *error = "more than three numbers in \"" + std::string(s) + "\"";
      return false;
    }
    if (i >= s.size() || s[i] < '0' || s[i] > '9') {
      *error = "expected a number at \"" + std::string(s.substr(i)) + "\" in \"" + std::string(s) + "\"";
      return false;
    }
    uint64_t v = 0;
    while (i < s.size() && s[i] >= '0' && s[i] <= '9') {
      v = v * 10 + uint64_t(s[i++] - '0');
      if (v > UINT32_MAX) {
        *error = "a number above 4294967295 in \"" + std::string(s) + "\"";
        return false;
      }
    }
    (*id)[count++] = uint32_t(v);
    skipSpaces();
    if (i == s.size()) break;
    if (s[i] != ',') {
      *error = "unexpected '" + std::string(1, s[i]) + "' in \"" + std::string(s) + "\"";
      return false;
    }
    ++i;
  }
  if (count < minCount) {
    *error = "\"" + std::string(s) + "\" has " + std::to_string(count) + " number(s), at least " +
             std::to_string(minCount) + " are needed";
    return false;
  }
  return true;
}

}  // namespace

bool parseRayTreeSelection(std::string_view text, RayTreeSelection* out, std::string* error) {
  *out = RayTreeSelection{};
  RayTreeSelection sel;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find(';', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view entry = text.substr(start, end - start);
    while (!entry.empty() && (entry.front() == ' ' || entry.front() == '\t')) entry.remove_prefix(1);
    while (!entry.empty() && (entry.back() == ' ' || entry.back() == '\t')) entry.remove_suffix(1);
    start = end + 1;
    if (entry.empty()) {
      if (end == text.size() && !sel.empty()) break;  // a trailing ';'
      *error = "an empty entry (entries are \"x,y[,z]\" or \"compute:x[,y[,z]]\", separated by ';')";
      return false;
    }
    constexpr std::string_view kCompute = "compute:";
    RayTreeId id;
    if (entry.substr(0, kCompute.size()) == kCompute) {
      if (!parseId(entry.substr(kCompute.size()), 1, &id, error)) return false;
      sel.computeIds.push_back(id);
    } else {
      if (!parseId(entry, 2, &id, error)) return false;
      sel.launchIds.push_back(id);
    }
  }
  for (auto* v : {&sel.launchIds, &sel.computeIds}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
  *out = std::move(sel);
  return true;
}

// ------------------------------------------------------------------------------------------------ recording

RayTreeNode* RayTreeInvocation::add(RayTreeNode::Kind kind) { return addTo(current, kind); }

RayTreeNode* RayTreeInvocation::addTo(RayTreeNode* parent, RayTreeNode::Kind kind) {
  if (nodes_ >= kMaxNodes) {
    truncated = true;
    return nullptr;
  }
  ++nodes_;
  parent->children.push_back(std::make_unique<RayTreeNode>());
  RayTreeNode* n = parent->children.back().get();
  n->kind = kind;
  return n;
}

namespace {

// A recorded ray query keeps, after accel's state in the query variable, which node it records into. The tag
// (the variable's address, scrambled) tells a recorded state from bytes never initialized by this runtime.
struct QueryTail {
  uint64_t tag;
  RayTreeInvocation* owner;
  RayTreeNode* node;
};
constexpr size_t kTailOffset = (sizeof(accel::RayQuery) + 15) / 16 * 16;
static_assert(kTailOffset + sizeof(QueryTail) <= abi::kRayQueryStateBytes,
              "the recorded query's node must fit the variable compiled code reserves");
constexpr uint64_t kTagKey = 0x7261797472656521ull;

QueryTail* tailOf(void* query) {
  auto* t = reinterpret_cast<QueryTail*>(static_cast<uint8_t*>(query) + kTailOffset);
  return t->tag == (reinterpret_cast<uintptr_t>(query) ^ kTagKey) && t->node ? t : nullptr;
}

void committedOf(const accel::RayQuery& q, RayTreeNode* n) {
  n->hasCommitted = q.committed.type != 0;
  if (n->hasCommitted) n->committed = treeHit(accel::queryHitInfo(q, true));
}

void recordInitialize(const abi::RayQueryScope* scope, void* query, const abi::TraceRayArgs* args) {
  const auto& s = *static_cast<const RayTreeInvocation::QueryScope*>(scope);
  rayQueryRuntime().initialize(s.inner, query, args);
  auto* tail = reinterpret_cast<QueryTail*>(static_cast<uint8_t*>(query) + kTailOffset);
  tail->tag = reinterpret_cast<uintptr_t>(query) ^ kTagKey;
  tail->owner = s.owner;
  tail->node = s.owner->add(RayTreeNode::Kind::Query);
  if (RayTreeNode* n = tail->node) {
    n->accelerationStructure = args->accelerationStructure;
    n->rayFlags = args->rayFlags;
    n->cullMask = args->cullMask & 0xFF;
    std::memcpy(n->origin, args->origin, sizeof n->origin);
    std::memcpy(n->direction, args->direction, sizeof n->direction);
    n->tMin = args->tMin;
    n->tMax = args->tMax;
  }
}

uint32_t recordProceed(void* query) {
  const uint32_t r = rayQueryRuntime().proceed(query);
  if (QueryTail* tail = tailOf(query)) {
    if (RayTreeNode* n = tail->owner->addTo(tail->node, RayTreeNode::Kind::Proceed)) {
      const auto& q = *static_cast<const accel::RayQuery*>(query);
      n->hasCandidate = r != 0;
      if (r) n->candidate = treeHit(accel::queryHitInfo(q, false));
      committedOf(q, n);
    }
  }
  return r;
}

// The calls that change the committed hit: the node after the call.
template <RayTreeNode::Kind K>
RayTreeNode* recordCall(void* query) {
  QueryTail* tail = tailOf(query);
  if (!tail) return nullptr;
  RayTreeNode* n = tail->owner->addTo(tail->node, K);
  if (n) committedOf(*static_cast<const accel::RayQuery*>(query), n);
  return n;
}

void recordTerminate(void* query) {
  rayQueryRuntime().terminate(query);
  recordCall<RayTreeNode::Kind::Terminate>(query);
}
void recordGenerate(void* query, float t) {
  rayQueryRuntime().generateIntersection(query, t);
  if (RayTreeNode* n = recordCall<RayTreeNode::Kind::Generate>(query)) n->t = t;
}
void recordConfirm(void* query) {
  rayQueryRuntime().confirmIntersection(query);
  recordCall<RayTreeNode::Kind::Confirm>(query);
}
void recordGet(void* query, uint32_t op, uint32_t committed, void* out) {
  rayQueryRuntime().get(query, op, committed, out);
}

const abi::RayQueryRuntime kRecordingRuntime = {&recordInitialize, &recordProceed, &recordTerminate,
                                                &recordGenerate,   &recordConfirm, &recordGet};

// A dispatch's scope (RayTreeRecorder::computeScope): the calling invocation is the context in args->payload.
void selectInitialize(const abi::RayQueryScope* scope, void* query, const abi::TraceRayArgs* args) {
  const auto& s = *static_cast<const RayTreeRecorder::ComputeScope*>(scope);
  const auto* ctx = static_cast<const abi::InvocationContext*>(args->payload);
  if (RayTreeInvocation* inv = ctx ? s.recorder->find(ctx->globalId) : nullptr) {
    inv->ran = true;
    recordInitialize(&inv->queries, query, args);
    return;
  }
  rayQueryRuntime().initialize(s.inner, query, args);
  // The variable may hold a named invocation's earlier query (the same stack slot in vkrt_group): not recorded now.
  reinterpret_cast<QueryTail*>(static_cast<uint8_t*>(query) + kTailOffset)->tag = 0;
}

const abi::RayQueryRuntime kComputeRuntime = {&selectInitialize, &recordProceed, &recordTerminate,
                                              &recordGenerate,   &recordConfirm, &recordGet};

}  // namespace

RayTreeRecorder::RayTreeRecorder(const std::vector<RayTreeId>& ids, RayQueryScope* queries) : invocations_(ids.size()) {
  for (size_t i = 0; i < ids.size(); ++i) {
    RayTreeInvocation& inv = invocations_[i];
    inv.id = ids[i];
    inv.queries.runtime = &kRecordingRuntime;
    inv.queries.inner = queries;
    inv.queries.owner = &inv;
  }
  compute_.runtime = &kComputeRuntime;
  compute_.recorder = this;
  compute_.inner = queries;
}

void RayTreeRecorder::setQueryScope(RayQueryScope* queries) {
  for (RayTreeInvocation& inv : invocations_) inv.queries.inner = queries;
  compute_.inner = queries;
}

RayTreeInvocation* RayTreeRecorder::find(const uint32_t id[3]) {
  const RayTreeId key{id[0], id[1], id[2]};
  auto it = std::lower_bound(invocations_.begin(), invocations_.end(), key,
                             [](const RayTreeInvocation& a, const RayTreeId& b) { return a.id < b; });
  return it != invocations_.end() && it->id == key ? &*it : nullptr;
}

bool RayTreeRecorder::anyIn(const uint32_t lo[3], const uint32_t size[3]) const {
  for (const RayTreeInvocation& inv : invocations_) {
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && inv.id[k] >= lo[k] && uint64_t(inv.id[k]) < uint64_t(lo[k]) + size[k];
    if (in) return true;
  }
  return false;
}

RayTreeHit treeHit(const accel::HitInfo& h) {
  RayTreeHit r;
  r.t = h.t;
  r.instanceIndex = h.instanceIndex;
  r.customIndex = h.customIndex;
  r.geometryIndex = h.geometryIndex;
  r.primitiveIndex = h.primitiveIndex;
  r.hitKind = h.hitKind;
  r.triangle = h.triangle;
  return r;
}

// ------------------------------------------------------------------------------------------------ output

namespace {

using Kind = RayTreeNode::Kind;

const char* kindName(Kind k) {
  switch (k) {
    case Kind::Shader: return "shader";
    case Kind::Trace: return "trace";
    case Kind::Candidate: return "candidate";
    case Kind::Report: return "report";
    case Kind::Query: return "query";
    case Kind::Proceed: return "proceed";
    case Kind::Confirm: return "confirm";
    case Kind::Generate: return "generate";
    case Kind::Terminate: return "terminate";
    case Kind::Note: break;
  }
  return "note";
}

const char* verdictName(RayTreeNode::Verdict v) {
  switch (v) {
    case RayTreeNode::Verdict::Accepted: return "accepted";
    case RayTreeNode::Verdict::Ignored: return "ignored";
    case RayTreeNode::Verdict::Terminated: return "terminated";
    case RayTreeNode::Verdict::Outside: return "outside";
    case RayTreeNode::Verdict::None: break;
  }
  return "none";
}

// Floats as the shortest text that reads back as the same float ("%.9g" always does).
std::string num(float f) {
  if (std::isnan(f)) return "null";  // a box candidate's t (none until reported); JSON has no NaN
  char b[32];
  for (int p = 6; p <= 9; ++p) {
    std::snprintf(b, sizeof b, "%.*g", p, double(f));
    if (std::strtof(b, nullptr) == f) break;
  }
  return b;
}
std::string hex(uint64_t v) {
  char b[24];
  std::snprintf(b, sizeof b, "0x%" PRIx64, v);
  return b;
}
std::string vec3(const float v[3]) { return num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]); }
std::string bytes(const std::vector<uint8_t>& b) {
  std::string s;
  char h[4];
  for (size_t i = 0; i < b.size(); ++i) {
    std::snprintf(h, sizeof h, "%02x", b[i]);
    if (i && i % 4 == 0) s += ' ';
    s += h;
  }
  return s;
}

std::string hitText(const RayTreeHit& h) {
  return std::string(h.triangle ? "triangle" : "aabb") + (std::isnan(h.t) ? "" : " t=" + num(h.t)) + " instance " +
         std::to_string(h.instanceIndex) + " (custom " + std::to_string(h.customIndex) + ") geometry " +
         std::to_string(h.geometryIndex) + " primitive " + std::to_string(h.primitiveIndex) + " hitKind " +
         hex(h.hitKind);
}

void text(const RayTreeNode& n, int depth, std::string& out) {
  const std::string pad(size_t(depth) * 2, ' ');
  switch (n.kind) {
    case Kind::Shader:
      out += pad + n.name;  // (the name says the stage)
      if (n.group >= 0)
        out +=
            ": group " + std::to_string(n.group) + ", record " + std::to_string(n.recordIndex) + " at " + hex(n.record);
      out += "\n";
      break;
    case Kind::Trace:
    case Kind::Query:
      out += pad + (n.kind == Kind::Trace ? "traceRay" : "rayQueryInitialize") + " as " + hex(n.accelerationStructure) +
             " origin (" + vec3(n.origin) + ") direction (" + vec3(n.direction) + ") tMin " + num(n.tMin) + " tMax " +
             num(n.tMax) + " flags " + hex(n.rayFlags) + " cullMask " + hex(n.cullMask);
      if (n.kind == Kind::Trace)
        out += " sbtOffset " + std::to_string(n.sbtOffset) + " sbtStride " + std::to_string(n.sbtStride) +
               " missIndex " + std::to_string(n.missIndex) + "\n" + pad + "  payload before: " + bytes(n.payloadBefore);
      out += "\n";
      break;
    case Kind::Candidate:
      out += pad + "candidate " + hitText(n.candidate) + ": " + verdictName(n.verdict) + "\n";
      break;
    case Kind::Report:
      out += pad + "reportIntersection t=" + num(n.candidate.t) + " hitKind " + hex(n.candidate.hitKind) + ": " +
             verdictName(n.verdict) + "\n";
      break;
    case Kind::Proceed:
      out += pad + "proceed: " + (n.hasCandidate ? "candidate " + hitText(n.candidate) : std::string("false"));
      out += n.hasCommitted ? "; committed " + hitText(n.committed) + "\n" : "\n";
      break;
    case Kind::Confirm:
    case Kind::Generate:
    case Kind::Terminate:
      out += pad + kindName(n.kind) + (n.kind == Kind::Generate ? " t=" + num(n.t) : std::string()) + ": " +
             (n.hasCommitted ? "committed " + hitText(n.committed) : std::string("no committed hit")) + "\n";
      break;
    case Kind::Note: out += pad + "note: " + n.name + "\n"; break;
  }
  for (const auto& c : n.children) text(*c, depth + 1, out);
  if (n.kind == Kind::Trace) {
    out += pad + "  " + (n.hasCommitted ? "committed " + hitText(n.committed) : std::string("miss")) + "\n";
    out += pad + "  payload after: " + bytes(n.payloadAfter) + "\n";
  }
}

std::string jsonString(const std::string& s) {
  std::string r = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += c;
    } else if (uint8_t(c) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", unsigned(uint8_t(c)));
      r += b;
    } else {
      r += c;
    }
  }
  return r + "\"";
}
std::string jsonHit(const RayTreeHit& h) {
  return std::string("{\"type\":\"") + (h.triangle ? "triangle" : "aabb") + "\",\"t\":" + num(h.t) +
         ",\"instanceIndex\":" + std::to_string(h.instanceIndex) +
         ",\"instanceCustomIndex\":" + std::to_string(h.customIndex) +
         ",\"geometryIndex\":" + std::to_string(h.geometryIndex) +
         ",\"primitiveIndex\":" + std::to_string(h.primitiveIndex) + ",\"hitKind\":" + std::to_string(h.hitKind) + "}";
}
std::string jsonVec(const float v[3]) { return "[" + num(v[0]) + "," + num(v[1]) + "," + num(v[2]) + "]"; }

void json(const RayTreeNode& n, std::string& out) {
  out += std::string("{\"kind\":\"") + kindName(n.kind) + "\"";
  switch (n.kind) {
    case Kind::Shader:
      out += ",\"stage\":\"" + std::string(n.stage) + "\",\"name\":" + jsonString(n.name);
      if (n.group >= 0)
        out += ",\"group\":" + std::to_string(n.group) + ",\"recordIndex\":" + std::to_string(n.recordIndex) +
               ",\"record\":\"" + hex(n.record) + "\"";
      break;
    case Kind::Trace:
    case Kind::Query:
      out += ",\"accelerationStructure\":\"" + hex(n.accelerationStructure) + "\",\"origin\":" + jsonVec(n.origin) +
             ",\"direction\":" + jsonVec(n.direction) + ",\"tMin\":" + num(n.tMin) + ",\"tMax\":" + num(n.tMax) +
             ",\"rayFlags\":" + std::to_string(n.rayFlags) + ",\"cullMask\":" + std::to_string(n.cullMask);
      if (n.kind == Kind::Trace)
        out += ",\"sbtOffset\":" + std::to_string(n.sbtOffset) + ",\"sbtStride\":" + std::to_string(n.sbtStride) +
               ",\"missIndex\":" + std::to_string(n.missIndex) + ",\"payloadBefore\":\"" + bytes(n.payloadBefore) +
               "\",\"payloadAfter\":\"" + bytes(n.payloadAfter) + "\"";
      break;
    case Kind::Candidate:
    case Kind::Report:
      out += ",\"candidate\":" + jsonHit(n.candidate) + ",\"verdict\":\"" + verdictName(n.verdict) + "\"";
      break;
    case Kind::Proceed:
      out += ",\"result\":" + std::string(n.hasCandidate ? "true" : "false");
      if (n.hasCandidate) out += ",\"candidate\":" + jsonHit(n.candidate);
      break;
    case Kind::Generate: out += ",\"t\":" + num(n.t); break;
    case Kind::Note: out += ",\"text\":" + jsonString(n.name); break;
    default: break;
  }
  if (n.kind == Kind::Trace || n.kind == Kind::Proceed || n.kind == Kind::Confirm || n.kind == Kind::Generate ||
      n.kind == Kind::Terminate)
    out += ",\"committed\":" + (n.hasCommitted ? jsonHit(n.committed) : std::string("null"));
  out += ",\"children\":[";
  for (size_t i = 0; i < n.children.size(); ++i) {
    if (i) out += ",";
    json(*n.children[i], out);
  }
  out += "]}";
}

std::string idText(const RayTreeId& id) {
  return std::to_string(id[0]) + "," + std::to_string(id[1]) + "," + std::to_string(id[2]);
}

}  // namespace

std::string rayTreeText(const RayTreeInvocation& inv, const RayTreeContext& ctx) {
  std::string out = "ray tree of " + std::string(ctx.compute ? "global invocation id " : "launch id ") +
                    idText(inv.id) + " in " + ctx.command + " #" + std::to_string(ctx.sequence) + " (pipeline " +
                    hex(ctx.pipeline) + ", " + (ctx.compute ? "workgroups " : "size ") + std::to_string(ctx.size[0]) +
                    "x" + std::to_string(ctx.size[1]) + "x" + std::to_string(ctx.size[2]) + ")\n";
  text(inv.root, 1, out);
  if (inv.truncated)
    out += "  (truncated: more than " + std::to_string(RayTreeInvocation::kMaxNodes) + " nodes were recorded)\n";
  return out;
}

std::string rayTreeJson(const RayTreeInvocation& inv, const RayTreeContext& ctx) {
  std::string out = "{\"command\":" + jsonString(ctx.command) + ",\"sequence\":" + std::to_string(ctx.sequence) +
                    ",\"pipeline\":\"" + hex(ctx.pipeline) + "\",\"" + (ctx.compute ? "workgroups" : "launchSize") +
                    "\":[" + std::to_string(ctx.size[0]) + "," + std::to_string(ctx.size[1]) + "," +
                    std::to_string(ctx.size[2]) + "],\"" + (ctx.compute ? "globalInvocationId" : "launchId") + "\":[" +
                    idText(inv.id) + "],\"truncated\":" + (inv.truncated ? "true" : "false") + ",\"tree\":";
  json(inv.root, out);
  return out + "}";
}

}  // namespace vkrt::exec
