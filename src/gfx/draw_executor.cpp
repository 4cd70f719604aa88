#include "gfx/draw_executor.hpp"

#include <cstdio>
#include <cstring>
#include <memory>
#include <string>

#include "abi/abi.hpp"
#include "exec/fiber_group.hpp"
#include "exec/ray_query.hpp"
#include "exec/supervise.hpp"
#include "exec/thread_pool.hpp"
#include "gfx/graphics_pipeline.hpp"
#include "gfx/graphics_state.hpp"
#include "gfx/vertex_input.hpp"
#include "raster/raster.hpp"
#include "runtime/acceleration_structure.hpp"
#include "runtime/bound_resources.hpp"
#include "runtime/buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/report.hpp"
#include "runtime/shader_messages.hpp"

namespace vkrt::gfx {
namespace {

using abi::GraphicsInvocation;
using abi::kGraphicsLocations;

// One worker's invocations and their input/output storage, reused for every vertex and quad it shades.
struct alignas(64) WorkerScratch {
  GraphicsInvocation inv[4];
  alignas(16) uint32_t inputs[4][kGraphicsLocations * 4];
  alignas(16) uint32_t outputs[4][kGraphicsLocations * 4];
  alignas(16) uint32_t outputs1[4][4];
  // The SPMD entry's outputs as structures of arrays (word w of lane l at [w][l]) where they are not written into
  // the quad's colours in place (quadOutputs).
  alignas(16) uint32_t outputsSoa[kGraphicsLocations * 4][4];
  alignas(16) uint32_t inputsSoa[kGraphicsLocations * 4][4];  // likewise the inputs, where not read in place
  alignas(16) uint8_t exchange[abi::kQuadExchangeBytes];
  alignas(16) uint8_t sink[abi::kSinkBytes];
  // The primitive and sample the invocations' per-primitive fields were last set for (shadeQuad), null: none yet.
  const void* primitive = nullptr;
  uint32_t sampleIndex = 0;
  const raster::FragmentQuad* quad = nullptr;  // the quad the in-place pointers were set for
};

}  // namespace

// One WorkerScratch per worker slot of the thread pool.
struct DrawScratch {
  std::unique_ptr<WorkerScratch[]> workers;
};

void DrawScratchDeleter::operator()(DrawScratch* s) const { delete s; }

namespace {

struct DrawContext {
  const GraphicsPipeline* pipeline = nullptr;
  exec::Job* job = nullptr;
  AttributeFetch attributes[kMaxVertexAttributes];
  uint32_t attributeCount = 0;
  uint32_t varyingCount = 0;
  uint8_t varyingLocation[raster::kMaxLocations] = {};
  uint32_t clipCount = 0, cullCount = 0;
  GraphicsInvocation vertexProto{}, fragmentProto{};
  abi::GraphicsEntry vertexEntry = nullptr, fragmentEntry = nullptr;
  bool quads = false;  // the fragment shader runs its four lanes together
  bool spmd = false;   // ... in one call of its SPMD entry (spirv/spmd.hpp), else as four fibers
  // The fragment shader's SPMD entry reads its inputs from the quad's slots in place (no copies per quad): the slots
  // are its input locations in order (slot s = location s); and writes its colour outputs into the quad's colours in
  // place: every output location is a colour attachment's. (Both sides are structures of arrays.)
  bool quadInputs = false, quadOutputs = false;
  bool writesDepth = false, writesSampleMask = false;  // FragDepth, SampleMask: else their fields are not copied
  bool canDiscard = false;  // else no lane's status ever leaves 0 (runTileTask's): not reset, not read per quad
  bool readsPointCoord = false, readsSampleMask = false;  // PointCoord, SampleMask in: else not set per lane and quad
  bool leanSpmd = false;  // spmd, quadInputs, quadOutputs, no FragDepth or SampleMask output: shadeQuadSpmd
  // Each lane's `helper` flag is set per quad: the scalar path and fibers read it, the SPMD entry (which takes its
  // helper lanes from the coverage, GraphicsInvocation::coverageSoa) only in a shader with side effects.
  bool helperFlags = true;
  uint32_t samples = 1;
  WorkerScratch* scratch = nullptr;  // per worker slot
};

// The standard sample positions ("Multisampling"): 1 sample at the centre, 4 in the standard pattern.
constexpr float kSamplePositions4[4][2] = {{0.375f, 0.125f}, {0.875f, 0.375f}, {0.125f, 0.625f}, {0.625f, 0.875f}};

struct VertexTask {
  DrawContext* c;
  WorkerScratch* w;
  uint32_t instanceIndex, viewIndex;
  const uint32_t* vertexIndex;
  uint32_t count;
  raster::ShadedVertex* out;
  uint32_t done;  // vertices completed (a supervised task may end early)
};

void shadeVerticesTask(void* arg) {
  VertexTask& t = *static_cast<VertexTask*>(arg);
  const DrawContext& c = *t.c;
  GraphicsInvocation& inv = t.w->inv[0];
  uint32_t* inputs = t.w->inputs[0];
  uint32_t* outputs = t.w->outputs[0];
  exec::setRunning(c.pipeline->vertexName.c_str(), nullptr, exec::Abort::NoId);
  for (uint32_t i = 0; i < t.count; ++i) {
    inv = c.vertexProto;
    inv.base.sink = t.w->sink;
    inv.inputs = inputs;
    inv.outputs = outputs;
    inv.outputs1 = t.w->outputs1[0];
    for (uint32_t a = 0; a < c.attributeCount; ++a)
      fetchAttribute(c.attributes[a], t.vertexIndex[i], t.instanceIndex, inputs);
    for (uint32_t s = 0; s < c.varyingCount; ++s) std::memset(outputs + 4 * c.varyingLocation[s], 0, 16);
    inv.vertexIndex = int32_t(t.vertexIndex[i]);
    inv.instanceIndex = int32_t(t.instanceIndex);
    inv.viewIndex = t.viewIndex;
    c.vertexEntry(&inv);
    raster::ShadedVertex& v = t.out[i];
    std::memcpy(v.position, inv.position, sizeof v.position);
    v.pointSize = inv.pointSize;
    for (uint32_t k = 0; k < c.clipCount; ++k) v.clipDistance[k] = inv.clipDistance[k];
    for (uint32_t k = 0; k < c.cullCount; ++k) v.clipDistance[c.clipCount + k] = inv.cullDistance[k];
    for (uint32_t s = 0; s < c.varyingCount; ++s)
      std::memcpy(v.varyings + 4 * s, outputs + 4 * c.varyingLocation[s], 16);
    t.done = i + 1;
  }
}

void shadeVertices(void* user, uint32_t instanceIndex, uint32_t viewIndex, const uint32_t* vertexIndex, uint32_t count,
                   raster::ShadedVertex* out, unsigned worker) {
  auto* c = static_cast<DrawContext*>(user);
  VertexTask t{c, &c->scratch[worker], instanceIndex, viewIndex, vertexIndex, count, out, 0};
  if (exec::runSupervised(*c->job, shadeVerticesTask, &t)) return;
  // The job ended (a fault, the watchdog, the device going away): the vertices not shaded collapse to one point,
  // so that their primitives cover nothing. The device is lost once the draw returns.
  for (uint32_t i = t.done; i < count; ++i) {
    raster::ShadedVertex& v = out[i];
    v.position[0] = v.position[1] = v.position[2] = 0;
    v.position[3] = 1;
    v.pointSize = 1;
    for (uint32_t k = 0; k < c->clipCount + c->cullCount; ++k) v.clipDistance[k] = 0;
    for (uint32_t s = 0; s < c->varyingCount; ++s) std::memset(v.varyings + 4 * s, 0, 16);
  }
}

// The fragment stage's supervision, once per tile (raster::FragmentStage::runTile): the worker's four invocations
// start from the draw's prototype here, so that a quad writes only the fields that change (shadeQuad); a fault or
// the watchdog in the tile's shader code ends the tile (and the job) through exec::runSupervised.
struct TileTask {
  DrawContext* c;
  WorkerScratch* w;
  void (*body)(void*);
  void* arg;
};

void runTileTask(void* arg) {
  TileTask& t = *static_cast<TileTask*>(arg);
  const DrawContext& c = *t.c;
  WorkerScratch& w = *t.w;
  exec::setRunning(c.pipeline->fragmentName.c_str(), nullptr, exec::Abort::NoId);
  for (uint32_t l = 0; l < 4; ++l) {
    GraphicsInvocation& inv = w.inv[l];
    inv = c.fragmentProto;
    inv.base.sink = w.sink;
    inv.base.localIndex = l;
    inv.base.workgroupMemory = w.exchange;
    inv.inputs = w.inputs[l];
    inv.outputs = w.outputs[l];
    inv.outputs1 = w.outputs1[l];
  }
  w.primitive = nullptr;
  w.quad = nullptr;
  t.body(t.arg);
}

bool runTile(void* user, void (*body)(void*), void* arg, unsigned worker) {
  auto* c = static_cast<DrawContext*>(user);
  TileTask t{c, &c->scratch[worker], body, arg};
  return exec::runSupervised(*c->job, runTileTask, &t);
}

// GraphicsInvocation::interpolateAt: the rasterizer evaluates the quad's inputs again.
void interpolateAt(const GraphicsInvocation* inv, uint32_t where, int32_t sample, float dx, float dy, uint32_t* out) {
  const auto at = where == abi::kInterpolateAtSample   ? raster::InterpolateAt::Sample
                  : where == abi::kInterpolateAtOffset ? raster::InterpolateAt::Offset
                                                       : raster::InterpolateAt::Centroid;
  raster::interpolateAt(*static_cast<const raster::FragmentQuad*>(inv->quad), inv->base.localIndex, at, sample, dx, dy,
                        out);
}

// What is the same for every quad of a primitive (and sample), in all four invocations (a lane that does not run now
// may run in the next quad): the per-primitive built-ins, and the in-place input and output pointers (the rasterizer
// hands every quad of a tile in the same FragmentQuad). Once per primitive: out of line.
[[gnu::noinline]] void setPrimitive(const DrawContext& c, WorkerScratch& w, raster::FragmentQuad& q) {
  w.primitive = q.primitive, w.sampleIndex = q.sampleIndex, w.quad = &q;
  float samplePosition[2] = {0.5f, 0.5f};
  if (c.samples == 4) {
    samplePosition[0] = kSamplePositions4[q.sampleIndex & 3][0];
    samplePosition[1] = kSamplePositions4[q.sampleIndex & 3][1];
  }
  if (c.spmd) {
    // The SPMD entry writes the four lanes' outputs as structures of arrays through lane 0's pointers
    // (spirv/spmd.hpp): the quad's colours themselves where every output is a colour attachment's.
    w.inv[0].outputs = c.quadOutputs ? &q.color[0][0][0] : &w.outputsSoa[0][0];
    w.inv[0].outputs1 = &q.color1[0][0];
    w.inv[0].inputs = c.quadInputs ? &q.inputs[0][0] : &w.inputsSoa[0][0];
    for (uint32_t l = 0; l < 4; ++l) w.inv[l].fragCoordSoa = &q.fragCoord[0][0], w.inv[l].coverageSoa = q.coverage;
  }
  for (uint32_t l = 0; l < 4; ++l) {
    GraphicsInvocation& inv = w.inv[l];
    inv.frontFacing = q.frontFacing ? 1 : 0;
    inv.primitiveId = int32_t(q.primitiveId);
    inv.viewIndex = q.viewIndex;
    inv.layer = q.layer;
    inv.sampleId = int32_t(q.sampleIndex);
    inv.samplePosition[0] = samplePosition[0];
    inv.samplePosition[1] = samplePosition[1];
    inv.quad = &q;
    // Preset once: only a shader that writes SampleMask or FragDepth changes these, and only then are they read.
    inv.sampleMaskOut = ~0u;
  }
}

// The per-lane built-ins a quad's shader reads from lane l's invocation: the helper flag, and PointCoord and SampleMask
// where it declares them (the flags are the caller's copies of DrawContext's).
inline void setLaneBuiltIns(GraphicsInvocation& inv, const raster::FragmentQuad& q, uint32_t l, bool readsPointCoord,
                            bool readsSampleMask, bool helperFlags) {
  const uint32_t coverage = q.coverage[l];
  if (readsPointCoord) {
    inv.pointCoord[0] = q.pointCoord[l][0];
    inv.pointCoord[1] = q.pointCoord[l][1];
  }
  if (readsSampleMask) inv.sampleMaskIn = coverage;
  if (helperFlags) inv.helper = coverage == 0;
}

// The covered lanes the SPMD entry killed or demoted (their status), as a lane mask.
inline uint32_t discardedLanes(const WorkerScratch& w, const raster::FragmentQuad& q) {
  uint32_t killed = 0;
  for (uint32_t l = 0; l < 4; ++l)
    killed |= uint32_t(q.coverage[l] != 0 && (w.inv[l].status & (abi::kFragmentKilled | abi::kFragmentDemoted))) << l;
  return killed;
}

// What every quad starts with: false when the job is ending (a fault or the watchdog on another worker: the rest of
// the tile writes nothing), else the quad's discards cleared and the per-primitive fields set where the primitive
// changed.
inline bool startQuad(const DrawContext& c, WorkerScratch& w, raster::FragmentQuad& q) {
  if (c.job->cancel.load(std::memory_order_relaxed)) {
    q.killed = 0xF;
    return false;
  }
  q.killed = 0;
  if (q.primitive != w.primitive || q.sampleIndex != w.sampleIndex || &q != w.quad) setPrimitive(c, w, q);
  return true;
}

// One quad, inside runTile's supervision (the fields runTileTask set stay as they are: no shader writes them).
void shadeQuad(void* user, raster::FragmentQuad& q, unsigned worker) {
  const DrawContext& c = *static_cast<DrawContext*>(user);
  WorkerScratch& w = c.scratch[worker];
  if (!startQuad(c, w, q)) return;
  // The context's flags as locals: the stores into the invocations below could alias the context, which would
  // otherwise be read again for every lane.
  const bool spmd = c.spmd, quadInputs = c.quadInputs, quadOutputs = c.quadOutputs;
  const bool writesDepth = c.writesDepth, writesSampleMask = c.writesSampleMask;
  // The lanes the fibers and the scalar path run: all four where they run together, else the covered ones (the SPMD
  // entry takes all four and masks the helpers itself).
  uint32_t lanes = 0xF;
  if (!spmd && !c.quads)
    lanes = (q.coverage[0] ? 1 : 0) | (q.coverage[1] ? 2 : 0) | (q.coverage[2] ? 4 : 0) | (q.coverage[3] ? 8 : 0);
  if (spmd && !quadInputs) {
    // The quad's slots at the shader's locations, the four lanes' words together.
    for (uint32_t s = 0; s < c.varyingCount; ++s)
      std::memcpy(w.inputsSoa[4 * c.varyingLocation[s]], q.inputs[4 * s], 4 * 16);
  }
  // The per-lane built-ins the entry reads from lane l's invocation.
  const bool canDiscard = c.canDiscard, readsPointCoord = c.readsPointCoord, readsSampleMask = c.readsSampleMask;
  const bool helperFlags = c.helperFlags;
  auto setLane = [&](uint32_t l) {
    GraphicsInvocation& inv = w.inv[l];
    setLaneBuiltIns(inv, q, l, readsPointCoord, readsSampleMask, helperFlags);
    if (writesSampleMask) inv.sampleMaskOut = ~0u;
    if (writesDepth) inv.fragDepth = q.fragCoord[2][l];
  };
  if (spmd) {
    // Every lane: the uncovered ones are helpers (the entry runs them only where the shader takes derivatives). The
    // SPMD entry keeps no quadParity (its derivatives are shuffles) and writes a status only where it discards.
    for (uint32_t l = 0; l < 4; ++l) {
      setLane(l);
      if (canDiscard) w.inv[l].status = 0;
    }
  } else {
    for (uint32_t l = 0; l < 4; ++l) {
      if (!(lanes & (1u << l))) continue;
      // The fibers' and the scalar path's inputs (the lane's words of each slot at the shader's locations) and
      // FragCoord; the SPMD entry reads the quad's own (inputs, fragCoordSoa).
      for (uint32_t s = 0; s < c.varyingCount; ++s)
        raster::laneWords(q.inputs + 4 * s, l, w.inputs[l] + 4 * c.varyingLocation[s]);
      for (uint32_t k = 0; k < 4; ++k) w.inv[l].fragCoord[k] = q.fragCoord[k][l];
      setLane(l);
      w.inv[l].status = 0;
      w.inv[l].quadParity = 0;
    }
  }
  if (spmd) {
    // The SPMD entry takes the quad's four invocations (the uncovered lanes are helpers: it runs them only where the
    // shader takes derivatives).
    w.inv[0].colorQuad = q.colorOut;
    c.fragmentEntry(w.inv);
  } else if (c.quads) {
    abi::InvocationContext* group[4] = {&w.inv[0].base, &w.inv[1].base, &w.inv[2].base, &w.inv[3].base};
    // A GraphicsInvocation starts with its InvocationContext: the fiber group calls the entry with the context's
    // address, which is the invocation's.
    if (!exec::runFiberGroup(reinterpret_cast<abi::ComputeEntry>(c.fragmentEntry), group, 4)) {
      q.killed = 0xF;  // no fiber stacks: nothing is written
      return;
    }
  } else {
    for (uint32_t l = 0; l < 4; ++l)
      if (lanes & (1u << l)) c.fragmentEntry(&w.inv[l]);
  }
  const uint32_t outputMask = c.pipeline->fragmentStage.outputMask;
  if (spmd && quadOutputs && !writesDepth && !writesSampleMask) {
    // The outputs are in the quad already: only discard is left to read.
    if (canDiscard) q.killed = discardedLanes(w, q);
    return;
  }
  for (uint32_t l = 0; l < 4; ++l) {
    if (!q.coverage[l]) continue;
    const GraphicsInvocation& inv = w.inv[l];
    if (inv.status & (abi::kFragmentKilled | abi::kFragmentDemoted)) {
      q.killed |= 1u << l;
      continue;
    }
    if (spmd && !quadOutputs) {
      for (uint32_t m = outputMask; m; m &= m - 1) {
        const uint32_t loc = uint32_t(__builtin_ctz(m));
        for (uint32_t k = 0; k < 4; ++k) q.color[loc][k][l] = w.outputsSoa[4 * loc + k][l];
      }
    } else if (!spmd) {
      // The fibers' and the scalar path's outputs, a lane's words together, into the quad's per-component arrays.
      for (uint32_t m = outputMask; m; m &= m - 1) {
        const uint32_t loc = uint32_t(__builtin_ctz(m));
        raster::setLaneWords(q.color[loc], l, w.outputs[l] + 4 * loc);
      }
      raster::setLaneWords(q.color1, l, w.outputs1[l]);
    }
    // Read by the rasterizer only when the shader writes them (FragmentStage::writesDepth, writesSampleMask).
    if (writesDepth) q.depth[l] = inv.fragDepth;
    if (writesSampleMask) q.sampleMaskOut[l] = inv.sampleMaskOut;
  }
}

// shadeQuad's commonest case on its own (DrawContext::leanSpmd: the SPMD entry reading its inputs from the quad and
// writing its colours there, no FragDepth or SampleMask output), with the small frame the case needs: per lane only
// the helper flag, and PointCoord, SampleMask and the status where the shader has them.
void shadeQuadSpmd(void* user, raster::FragmentQuad& q, unsigned worker) {
  const DrawContext& c = *static_cast<DrawContext*>(user);
  WorkerScratch& w = c.scratch[worker];
  if (!startQuad(c, w, q)) return;
  const bool canDiscard = c.canDiscard, readsPointCoord = c.readsPointCoord, readsSampleMask = c.readsSampleMask;
  if (canDiscard || readsPointCoord || readsSampleMask || c.helperFlags) {
    const bool helperFlags = c.helperFlags;
    for (uint32_t l = 0; l < 4; ++l) {
      setLaneBuiltIns(w.inv[l], q, l, readsPointCoord, readsSampleMask, helperFlags);
      if (canDiscard) w.inv[l].status = 0;
    }
  }
  w.inv[0].colorQuad = q.colorOut;
  c.fragmentEntry(w.inv);
  if (canDiscard) q.killed = discardedLanes(w, q);
}

// VUID-<command>-<suffix>.
struct Vuid {
  char text[96];
  Vuid(const char* command, const char* suffix) { std::snprintf(text, sizeof text, "VUID-%s-%s", command, suffix); }
};

// The draw-time VUID of a dynamic state that was not set.
const char* missingStateSuffix(uint32_t bit, uint32_t mask) {
  const bool vp = mask & (1u << kDynViewportWithCount), sc = mask & (1u << kDynScissorWithCount);
  switch (bit) {
    case kDynViewportWithCount: return sc ? "viewportCount-03419" : "viewportCount-03417";
    case kDynScissorWithCount: return vp ? "viewportCount-03419" : "scissorCount-03418";
    case kDynTopology: return "primitiveTopology-03420";
    case kDynRasterizerDiscardEnable: return "None-04876";
    case kDynDepthBiasEnable: return "None-04877";
    case kDynPrimitiveRestartEnable: return "None-04879";
    case kDynLogicOp: return "logicOp-04878";
    default: return "commandBuffer-02701";
  }
}

// The checks that need the bound pipeline; false after reporting.
bool checkDraw(const CommandBuffer* cb, const GraphicsPipeline& p, DrawExecState& d, const PassExecState& pass,
               const DrawParams& params, const char* command) {
  // VUID-vkCmdDraw-colorAttachmentCount-06179 (dynamic rendering) / VUID-vkCmdDraw-renderPass-02684 (a render pass
  // whose subpass has another number of color attachments is not compatible)
  // (A pipeline without fragment output state, rasterization statically discarded, writes no attachment.)
  // A subpass without color attachments takes any pColorBlendState->attachmentCount (VUID-VkGraphicsPipelineCreateInfo-
  // renderPass-06042 binds the count only "if the subpass uses color attachments"; the CTS's barrier.*_to_frag
  // cases draw so, with one blend attachment state, in a render pass of no attachment).
  const bool anyCount = !p.dynamicRendering && pass.target.colorCount == 0;
  if (p.fragmentOutput && p.colorCount != pass.target.colorCount && !anyCount) {
    Vuid v(command, p.dynamicRendering ? "colorAttachmentCount-06179" : "renderPass-02684");
    report(cb, Severity::Error, v.text,
           "%s: the bound graphics pipeline was created for %u color attachments, the render pass instance has %u; "
           "the draw is skipped",
           command, p.colorCount, pass.target.colorCount);
    return false;
  }
  // VUID-vkCmdDraw-viewMask-06178
  if (p.dynamicRendering && p.viewMask != pass.target.viewMask) {
    Vuid v(command, "viewMask-06178");
    report(cb, Severity::Error, v.text,
           "%s: the bound graphics pipeline's viewMask 0x%x differs from the render pass instance's 0x%x; the draw is "
           "skipped",
           command, p.viewMask, pass.target.viewMask);
    return false;
  }
  const uint32_t missing = p.dynamicMask & ~d.dynamicSet & ~(1u << kDynVertexStride);
  if (missing) {
    const uint32_t bit = uint32_t(__builtin_ctz(missing));
    // VUID-vkCmdDraw-commandBuffer-02701, -viewportCount-03417, -scissorCount-03418, -viewportCount-03419,
    // -primitiveTopology-03420, -None-04876, -None-04877, -None-04879, -logicOp-04878
    Vuid v(command, missingStateSuffix(bit, p.dynamicMask));
    report(cb, Severity::Error, v.text,
           "%s: the bound graphics pipeline has %s dynamic, but it was not set since it was last made undefined; the "
           "draw is skipped",
           command, dynamicStateName(bit));
    return false;
  }
  if ((p.dynamicMask & (1u << kDynViewportWithCount)) && (p.dynamicMask & (1u << kDynScissorWithCount)) &&
      d.dynamic.viewportCount != d.scissorCount) {
    // VUID-vkCmdDraw-viewportCount-03419 (both counts dynamic: they must match)
    Vuid v(command, "viewportCount-03419");
    report(cb, Severity::Error, v.text, "%s: viewportCount %u and scissorCount %u differ; the draw is skipped", command,
           d.dynamic.viewportCount, d.scissorCount);
    return false;
  }
  // VUID-vkCmdDraw-None-04007 (every binding the vertex shader's inputs read has a buffer bound)
  if (const uint32_t unbound = p.usedBindings & ~d.vertexBound) {
    Vuid v(command, "None-04007");
    report(cb, Severity::Error, v.text,
           "%s: vertex binding %u, which the vertex shader's inputs read, has no buffer bound; the draw is skipped",
           command, unsigned(__builtin_ctz(unbound)));
    return false;
  }
  // VUID-vkCmdDraw-pStrides-04884
  if ((p.dynamicMask & (1u << kDynVertexStride)) && (p.usedBindings & ~d.strideSet)) {
    Vuid v(command, "pStrides-04884");
    report(cb, Severity::Error, v.text,
           "%s: the pipeline's vertex strides are dynamic but binding %u was not bound by vkCmdBindVertexBuffers2 with "
           "pStrides; the draw is skipped",
           command, unsigned(__builtin_ctz(p.usedBindings & ~d.strideSet)));
    return false;
  }
  // VUID-vkCmdDrawIndexed-None-07312
  if (params.indexed && !d.indexBuffer) {
    Vuid v(command, "None-07312");
    report(cb, Severity::Error, v.text, "%s: no index buffer is bound; the draw is skipped", command);
    return false;
  }
  return true;
}

}  // namespace

void executeDraw(const CommandBuffer* cb, ExecState& st, const DrawParams& params, const char* command) {
  GraphicsExecState& gs = execState(st);
  DrawExecState& d = gs.draw;
  const Pipeline* bound = st.graphics.pipeline;
  // VUID-vkCmdDraw-None-02700
  if (!bound || bound->bindPoint != VK_PIPELINE_BIND_POINT_GRAPHICS) {
    Vuid v(command, "None-02700");
    report(cb, Severity::Error, v.text, "%s: no graphics pipeline is bound; the draw is skipped", command);
    return;
  }
  const auto& p = static_cast<const GraphicsPipeline&>(*bound);
  if (d.lastPipeline != &p) {
    d.dynamicSet &= p.dynamicMask;  // the new pipeline's static state replaces what was set
    d.lastPipeline = &p;
  }
  if (!gs.pass.active) return;  // reported when the draw was recorded (VUID-vkCmdDraw-renderpass)
  if (!checkDraw(cb, p, d, gs.pass, params, command)) return;
  if (params.count == 0 || params.instanceCount == 0) return;

  raster::State state;
  resolveState(p, d, &state);

  DrawContext c;
  c.pipeline = &p;
  c.vertexEntry = p.vertex->graphicsEntry;
  c.fragmentEntry = p.fragment ? p.fragment->graphicsEntry : nullptr;
  c.quads = p.fragment && p.fragment->graphics.needsQuad;
  c.spmd = p.fragment && p.fragment->spmdLanes == 4;
  c.samples = state.samples;
  c.clipCount = p.vertex->graphics.clipDistances;
  c.cullCount = p.vertex->graphics.cullDistances;
  for (const GraphicsPipeline::Attribute& a : p.attributes) {
    AttributeFetch& f = c.attributes[c.attributeCount++];
    const VertexBufferBinding& b = d.vertex[a.binding];
    f.format = a.format;
    f.location = a.location;
    f.base = b.buffer ? b.buffer->data() + b.offset : nullptr;
    f.size = b.size;
    f.offset = a.offset;
    f.stride = (p.dynamicMask & (1u << kDynVertexStride)) ? b.stride : p.bindings[a.binding].stride;
    f.perInstance = p.bindings[a.binding].perInstance;
  }
  c.varyingCount = p.varyingCount;
  for (uint32_t s = 0; s < p.varyingCount; ++s) c.varyingLocation[s] = p.fragmentStage.inputs[s].location;
  if (p.fragment) {
    const spirv::GraphicsStageInfo& fi = p.fragment->graphics;
    c.quadInputs = fi.inputs.size() == p.varyingCount && raster::kMaxLocations * 4 >= kGraphicsLocations * 4;
    for (uint32_t s = 0; s < fi.inputs.size(); ++s)
      c.quadInputs = c.quadInputs && fi.inputs[s].location == s && !fi.inputs[s].wide && c.varyingLocation[s] == s;
    c.writesDepth = fi.writesDepth;
    c.canDiscard = fi.canDiscard;
    c.readsPointCoord = fi.readsPointCoord;
    c.readsSampleMask = fi.readsSampleMask;
    c.writesSampleMask = fi.writesSampleMask;
    c.quadOutputs = true;
    for (const auto& out : fi.outputs)
      c.quadOutputs = c.quadOutputs && out.location < raster::kMaxColorAttachments && !out.wide;
    c.leanSpmd = c.spmd && c.quadInputs && c.quadOutputs && !c.writesDepth && !c.writesSampleMask;
    c.helperFlags = !c.spmd || fi.sideEffects;
  }

  // Descriptor sets, as compute dispatches resolve them (runtime/bound_resources.hpp).
  Vuid unbound(command, "None-02697");
  BoundResources vsResources, fsResources;
  vsResources.resolve(*p.vertex, st.graphics, cb, command, unbound.text);
  if (p.fragment) fsResources.resolve(*p.fragment, st.graphics, cb, command, unbound.text);

  // Ray queries in vertex and fragment shaders resolve acceleration structures as a dispatch's do.
  DispatchStructures structures(cb->device, cb, command);
  exec::RayQueryScope rayQueries(&structures);
  Device* dev = cb->device;
  exec::Job job(dev, dev->shaderTimeoutMs);
  if (dev->halted()) return;
  c.job = &job;
  for (GraphicsInvocation* proto : {&c.vertexProto, &c.fragmentProto}) {
    proto->base.pushConstants = st.pushConstants;
    proto->base.rayQueries = &rayQueries;
    proto->base.cancel = reinterpret_cast<const uint32_t*>(&job.cancel);
    proto->base.cancelled = &exec::cancelled;
    proto->base.workgroupSize[0] = proto->base.workgroupSize[1] = proto->base.workgroupSize[2] = 1;
    proto->baseVertex = params.indexed ? params.vertexOffset : int32_t(params.firstVertex);
    proto->baseInstance = int32_t(params.firstInstance);
    proto->drawIndex = int32_t(params.drawIndex);
    proto->position[3] = 1.0f;
    proto->pointSize = 1.0f;
  }
  c.vertexProto.base.resources = vsResources.slots();
  c.fragmentProto.base.resources = fsResources.slots();
  c.fragmentProto.interpolateAt = interpolateAt;
  // Per-worker scratch, made once per command buffer execution (the pool's worker slots do not change).
  if (!d.scratch) {
    d.scratch.reset(new DrawScratch);
    d.scratch->workers.reset(new WorkerScratch[exec::ThreadPool::instance().workerSlots()]());
  }
  c.scratch = d.scratch->workers.get();

  raster::VertexStage vertex;
  vertex.user = &c;
  vertex.shade = shadeVertices;
  vertex.clipDistanceCount = c.clipCount;
  vertex.cullDistanceCount = c.cullCount;
  raster::FragmentStage fragment = p.fragmentStage;
  fragment.user = &c;
  fragment.shade = !p.fragment ? nullptr : c.leanSpmd ? shadeQuadSpmd : shadeQuad;
  fragment.runTile = p.fragment ? runTile : nullptr;
  // The SPMD entry writes colour attachment 0 of the quads the rasterizer gives it an address for, where it was
  // compiled for this attachment's format (the pipeline's render pass or rendering formats; a compatible render pass
  // has the same) and the attachment is the draw's only one.
  const raster::Target& tg = gs.pass.target;
  if (c.spmd && p.fragment->graphics.mergesColor && tg.colorCount == 1 && tg.color[0].base) {
    const raster::ColorFormat::Layout layout = tg.colorFormat[0].layout;
    fragment.mergesColor0 =
        (p.colorMerge.format == abi::ColorMerge::kRgba8Unorm && layout == raster::ColorFormat::Layout::RGBA8UNorm) ||
        (p.colorMerge.format == abi::ColorMerge::kBgra8Unorm && layout == raster::ColorFormat::Layout::BGRA8UNorm);
    c.fragmentProto.colorPitch = int64_t(tg.color[0].rowPitch);
  }

  raster::Draw draw;
  draw.count = params.count;
  draw.instanceCount = params.instanceCount;
  draw.firstVertex = params.firstVertex;
  draw.vertexOffset = params.vertexOffset;
  draw.firstInstance = params.firstInstance;
  draw.varyingCount = p.varyingCount;
  draw.samplesPassed = d.occlusion;
  if (params.indexed) {
    draw.indexType = d.indexType;
    const uint64_t size = d.indexType == raster::IndexType::UInt16  ? 2
                          : d.indexType == raster::IndexType::UInt8 ? 1
                                                                    : 4;
    const uint64_t start = d.indexOffset + uint64_t(params.firstIndex) * size;
    const uint64_t bufferSize = d.indexBuffer->size;
    draw.indices = d.indexBuffer->data() + (start < bufferSize ? start : bufferSize);
    draw.indexBytes = start < bufferSize ? bufferSize - start : 0;
  }
  raster::draw(gs.pass.target, state, draw, vertex, fragment);
  if (job.aborted()) dev->shaderAborted(&p, command, job.abort());
  // Both stages read the same bound sets: whichever uses the binding names its descriptor.
  DescriptorNamer vsNames = descriptorNamer(*p.vertex, vsResources.slots());
  DescriptorNamer fsNames = p.fragment ? descriptorNamer(*p.fragment, fsResources.slots()) : DescriptorNamer();
  deliverShaderMessages(cb, &p, command, job.messages, [&](uint32_t set, uint32_t binding, uint64_t element) {
    std::string name = vsNames(set, binding, element);
    return name.empty() && fsNames ? fsNames(set, binding, element) : name;
  });
}

}  // namespace vkrt::gfx
