// The ray tree of chosen invocations (VKRT_RAY_TREE, docs/ray-tree.md): every traceRayEXT and ray query of a
// named ray tracing launch id or compute global invocation id, with its arguments, the candidates the traversal
// offered to a shader (any-hit verdicts, intersection reports), the committed hit, the shaders run (stage, group,
// SBT record) and the payload before and after, nested traces as children; as indented text and as JSON.
//
// Cost: a launch or dispatch gets a RayTreeRecorder only when the setting names invocations of its kind (the caller
// decides once per launch); without one the executors test one null pointer per trace. With one, each raygen
// invocation (each compute workgroup) is looked up once in the recorder's small sorted list, and only the named
// invocations record (on their own thread: no lock). Nothing is compiled into shaders: the executors record what
// they see at the runtime calls (trace, any-hit, intersection, ray query calls).
//
// No Vulkan object here: the caller (src/rt, src/runtime) parses the setting, names the command and pipeline, and
// delivers the text.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "abi/abi.hpp"
#include "accel/accel.hpp"

namespace vkrt::exec {

class RayQueryScope;

using RayTreeId = std::array<uint32_t, 3>;

// VKRT_RAY_TREE's value: entries separated by ';', each `x,y[,z]` (a ray tracing launch id; z defaults to 0) or
// `compute:x[,y[,z]]` (a compute global invocation id; y and z default to 0). Numbers are decimal, spaces
// around them are allowed. Both lists are sorted and without duplicates.
struct RayTreeSelection {
  std::vector<RayTreeId> launchIds;
  std::vector<RayTreeId> computeIds;
  bool empty() const { return launchIds.empty() && computeIds.empty(); }
};

// Parses `text`; false with `error` set (what is wrong and where) on malformed input.
bool parseRayTreeSelection(std::string_view text, RayTreeSelection* out, std::string* error);

// A candidate or committed hit as recorded.
struct RayTreeHit {
  float t = 0;
  uint32_t instanceIndex = 0, customIndex = 0, geometryIndex = 0, primitiveIndex = 0, hitKind = 0;
  bool triangle = true;
};

struct RayTreeNode {
  enum class Kind : uint8_t {
    Shader,     // a shader run: stage, group, SBT record; children: its traces, queries, callables (and reports)
    Trace,      // traceRayEXT: arguments, payload before and after, committed hit; children: candidates, shaders
    Candidate,  // a candidate the traversal offered to a shader: the hit, the verdict; child: that shader
    Report,     // reportIntersectionEXT: t, hit kind, verdict; child: the any-hit shader
    Query,      // rayQueryInitializeEXT: arguments; children: the calls on the query
    Proceed,    // rayQueryProceedEXT: the candidate returned (none: false) and the committed hit after it
    Confirm,    // rayQueryConfirmIntersectionEXT
    Generate,   // rayQueryGenerateIntersectionEXT(t)
    Terminate,  // rayQueryTerminateEXT
    Note,       // what the executor did instead (a trace past the recursion depth, a shader past the stack size)
  };
  enum class Verdict : uint8_t { None, Accepted, Ignored, Terminated, Outside };
  Kind kind = Kind::Shader;
  // Shader
  const char* stage = "";
  std::string name;          // the shader's description (entry point)
  int64_t group = -1;        // the pipeline's group index (-1: none, a compute shader)
  uint64_t recordIndex = 0;  // in its SBT region
  uint64_t record = 0;       // the SBT record's address
  // Trace, Query
  uint64_t accelerationStructure = 0;
  uint32_t rayFlags = 0, cullMask = 0, sbtOffset = 0, sbtStride = 0, missIndex = 0;
  float origin[3] = {}, direction[3] = {}, tMin = 0, tMax = 0;
  std::vector<uint8_t> payloadBefore, payloadAfter;
  // Candidate, Report, Proceed: the candidate; Trace, Proceed, Confirm, Generate: the committed hit after it
  bool hasCandidate = false, hasCommitted = false;
  RayTreeHit candidate, committed;
  Verdict verdict = Verdict::None;
  float t = 0;  // Generate
  std::vector<std::unique_ptr<RayTreeNode>> children;
};

// One named invocation's tree. Used by one thread at a time (the one running the invocation).
class RayTreeInvocation {
 public:
  static constexpr size_t kMaxNodes = 1u << 16;  // beyond it nothing more is recorded (the output says so)

  RayTreeId id{};
  RayTreeNode root;              // the raygen (or compute) shader
  RayTreeNode* current = &root;  // where the next node goes
  bool ran = false;
  bool truncated = false;

  // A new node of `kind` under `current`, or null once kMaxNodes are recorded.
  RayTreeNode* add(RayTreeNode::Kind kind);
  // The same under `parent` (a ray query's node: its calls go there wherever the shader is).
  RayTreeNode* addTo(RayTreeNode* parent, RayTreeNode::Kind kind);
  // Makes `node` current until destroyed (nothing when `node` is null).
  class Enter {
   public:
    Enter(RayTreeInvocation* inv, RayTreeNode* node) : inv_(node ? inv : nullptr) {
      if (inv_) {
        saved_ = inv_->current;
        inv_->current = node;
      }
    }
    ~Enter() {
      if (inv_) inv_->current = saved_;
    }
    Enter(const Enter&) = delete;
    Enter& operator=(const Enter&) = delete;

   private:
    RayTreeInvocation* inv_;
    RayTreeNode* saved_ = nullptr;
  };

  // The ray query scope this invocation's shaders get: it records, then calls the launch's or dispatch's own.
  struct QueryScope : abi::RayQueryScope {
    RayQueryScope* inner = nullptr;
    RayTreeInvocation* owner = nullptr;
  } queries;

 private:
  size_t nodes_ = 0;
};

// The named invocations of one launch or dispatch.
class RayTreeRecorder {
 public:
  // `ids` sorted and unique (RayTreeSelection's); `queries`: the scope the recorded invocations' ray queries use.
  RayTreeRecorder(const std::vector<RayTreeId>& ids, RayQueryScope* queries = nullptr);
  // The scope the recorded invocations' ray queries resolve through (the executor's, set when the launch starts).
  void setQueryScope(RayQueryScope* queries);
  // The scope of every invocation of a dispatch (compute ids): each rayQueryInitialize finds its invocation by the
  // global id in the context compute shaders pass in TraceRayArgs::payload, and records where that id is named;
  // the others go to setQueryScope's scope unrecorded.
  const abi::RayQueryScope* computeScope() const { return &compute_; }
  // The invocation `id` names, or null: a bisection of the small sorted list.
  RayTreeInvocation* find(const uint32_t id[3]);
  // Whether an id lies in the box [lo, lo + size) (a compute workgroup).
  bool anyIn(const uint32_t lo[3], const uint32_t size[3]) const;
  std::vector<RayTreeInvocation>& invocations() { return invocations_; }

  struct ComputeScope : abi::RayQueryScope {
    RayTreeRecorder* recorder = nullptr;
    RayQueryScope* inner = nullptr;
  };

 private:
  std::vector<RayTreeInvocation> invocations_;
  ComputeScope compute_;
};

// Converts a traversal hit.
RayTreeHit treeHit(const accel::HitInfo& h);

// What the caller names about the launch or dispatch in the output.
struct RayTreeContext {
  std::string command;  // "vkCmdTraceRaysKHR", "vkCmdDispatch", ...
  uint64_t pipeline = 0;
  uint64_t sequence = 0;  // the device's count of recorded launches and dispatches
  uint32_t size[3] = {1, 1, 1};
  bool compute = false;  // ids are global invocation ids (else launch ids)
};

// The indented text and the JSON object (one line) of a recorded invocation.
std::string rayTreeText(const RayTreeInvocation& inv, const RayTreeContext& ctx);
std::string rayTreeJson(const RayTreeInvocation& inv, const RayTreeContext& ctx);

}  // namespace vkrt::exec
