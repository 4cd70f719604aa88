// draw(): vertex shading of the draw's unique vertices, primitive assembly ("Drawing Commands", "Primitive
// Topologies"), then per batch of instances the parallel setup of primitives, the binning into tiles and the
// parallel rasterization of the tiles (each tile keeps the draw's primitive order).
#include <algorithm>
#include <cmath>

#include "exec/thread_pool.hpp"
#include "raster/internal.hpp"

namespace vkrt::raster {
namespace {

using detail::AssembledPrim;
using detail::DrawContext;
using detail::kTileSize;
using detail::SetupTri;

constexpr uint32_t kRestart = ~0u;
constexpr uint32_t kVertexChunk = 64;            // vertices per vertex-shading task
constexpr uint32_t kPrimChunk = 256;             // primitives per setup task
constexpr uint64_t kBatchVertices = 1u << 18;    // shaded vertices held at once (instances are batched by this)
constexpr size_t kKeepBytes = size_t(64) << 20;  // per-thread storage kept between draws
constexpr float kGuardPixels = 65536.0f;         // framebuffer coordinates stay within +-2^16 pixels (fixed point 2^24)

// A primitive as slots into the draw's unique vertices.
struct PrimRef {
  uint32_t v[3];
  uint8_t count, provoking;
  uint32_t primitiveId;
};

// The unique vertices of the draw (their vertex indices) and, per index of the draw, its slot (or kRestart).
struct VertexSet {
  std::vector<uint32_t> vertexIndex;
  std::vector<uint32_t> slots;
};

uint32_t readIndex(const Draw& d, uint32_t i, uint32_t& restartValue) {
  const uint32_t size = d.indexType == IndexType::UInt16 ? 2 : d.indexType == IndexType::UInt8 ? 1 : 4;
  restartValue = d.indexType == IndexType::UInt16 ? 0xFFFFu : d.indexType == IndexType::UInt8 ? 0xFFu : 0xFFFFFFFFu;
  const uint64_t offset = uint64_t(i) * size;
  if (offset + size > d.indexBytes) return 0;  // robustness: reads past the index buffer give 0
  const uint8_t* p = static_cast<const uint8_t*>(d.indices) + offset;
  if (size == 1) return *p;
  if (size == 2) {
    uint16_t v;
    std::memcpy(&v, p, 2);
    return v;
  }
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

VertexSet uniqueVertices(const State& st, const Draw& d) {
  VertexSet set;
  set.slots.resize(d.count);
  if (d.indexType == IndexType::None) {
    set.vertexIndex.resize(d.count);
    for (uint32_t i = 0; i < d.count; ++i) set.vertexIndex[i] = d.firstVertex + i, set.slots[i] = i;
    return set;
  }
  std::vector<uint32_t> raw(d.count);
  uint32_t lo = ~0u, hi = 0;
  for (uint32_t i = 0; i < d.count; ++i) {
    uint32_t restart;
    raw[i] = readIndex(d, i, restart);
    if (st.primitiveRestart && raw[i] == restart) {
      raw[i] = kRestart;
      continue;
    }
    lo = std::min(lo, raw[i]), hi = std::max(hi, raw[i]);
  }
  if (lo > hi) {
    std::fill(set.slots.begin(), set.slots.end(), kRestart);
    return set;
  }
  const uint64_t range = uint64_t(hi) - lo + 1;
  if (range <= std::max<uint64_t>(4ull * d.count, 65536)) {
    std::vector<uint32_t> table(range, kRestart);  // index - lo -> slot, in order of first use
    for (uint32_t i = 0; i < d.count; ++i) {
      if (raw[i] == kRestart) {
        set.slots[i] = kRestart;
        continue;
      }
      uint32_t& slot = table[raw[i] - lo];
      if (slot == kRestart) {
        slot = uint32_t(set.vertexIndex.size());
        set.vertexIndex.push_back(raw[i] + uint32_t(d.vertexOffset));
      }
      set.slots[i] = slot;
    }
    return set;
  }
  std::vector<uint32_t> sorted;
  for (uint32_t v : raw)
    if (v != kRestart) sorted.push_back(v);
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  for (uint32_t v : sorted) set.vertexIndex.push_back(v + uint32_t(d.vertexOffset));
  for (uint32_t i = 0; i < d.count; ++i) {
    set.slots[i] = raw[i] == kRestart
                       ? kRestart
                       : uint32_t(std::lower_bound(sorted.begin(), sorted.end(), raw[i]) - sorted.begin());
  }
  return set;
}

// Primitive assembly ("Primitive Topologies"): vertex order and provoking vertex per topology; a restart index
// ends the current strip, fan or incomplete primitive. Primitive IDs count the primitives of the instance.
std::vector<PrimRef> assemble(const State& st, const std::vector<uint32_t>& slots) {
  std::vector<PrimRef> prims;
  const bool last = st.lastVertexProvoking;
  uint32_t run[6];  // the current run's vertices (window)
  uint32_t n = 0;   // vertices in the current run so far
  uint32_t id = 0;
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c, uint8_t count, uint8_t provoking) {
    prims.push_back(PrimRef{{a, b, c}, count, provoking, id++});
  };
  for (uint32_t s : slots) {
    if (s == kRestart) {
      n = 0;
      continue;
    }
    switch (st.topology) {
      case Topology::PointList: emit(s, s, s, 1, 0); break;
      case Topology::LineList:
        run[n++] = s;
        if (n == 2) emit(run[0], run[1], run[1], 2, last ? 1 : 0), n = 0;
        break;
      case Topology::LineStrip:
        if (n) emit(run[0], s, s, 2, last ? 1 : 0);
        run[0] = s, n = 1;
        break;
      case Topology::TriangleList:
        run[n++] = s;
        if (n == 3) emit(run[0], run[1], run[2], 3, last ? 2 : 0), n = 0;
        break;
      case Topology::TriangleStrip:
        if (n >= 2) {
          // Triangle i = n - 2: (v_i, v_i+1, v_i+2) when even, (v_i, v_i+2, v_i+1) when odd (same winding as
          // the even ones); the last-vertex convention provokes with v_i+2.
          if ((n & 1) == 0) {
            emit(run[0], run[1], s, 3, last ? 2 : 0);
          } else {
            emit(run[0], s, run[1], 3, last ? 1 : 0);
          }
          run[0] = run[1];
        } else {
          run[n] = s;
        }
        if (n >= 2) run[1] = s;
        ++n;
        break;
      case Topology::TriangleFan:
        // Triangle i: (v_i+1, v_i+2, v_0); provoking v_i+1, or v_i+2 with the last-vertex convention.
        if (n >= 2) emit(run[1], s, run[0], 3, last ? 1 : 0);
        if (n >= 1)
          run[1] = s;
        else
          run[0] = s;
        ++n;
        break;
      case Topology::LineListWithAdjacency:
        run[n++] = s;
        if (n == 4) emit(run[1], run[2], run[2], 2, last ? 1 : 0), n = 0;
        break;
      case Topology::LineStripWithAdjacency:
        if (n < 3) {
          run[n++] = s;
        } else {
          emit(run[1], run[2], run[2], 2, last ? 1 : 0);
          run[0] = run[1], run[1] = run[2], run[2] = s;
        }
        break;
      case Topology::TriangleListWithAdjacency:
        run[n++] = s;
        if (n == 6) emit(run[0], run[2], run[4], 3, last ? 2 : 0), n = 0;
        break;
      default: break;  // strips with adjacency and patches: not supported (never reach the rasterizer)
    }
  }
  return prims;
}

Rect intersect(const Rect& a, const Rect& b) {
  const int64_t x0 = std::max<int64_t>(a.x, b.x), y0 = std::max<int64_t>(a.y, b.y);
  const int64_t x1 = std::min<int64_t>(int64_t(a.x) + a.width, int64_t(b.x) + b.width);
  const int64_t y1 = std::min<int64_t>(int64_t(a.y) + a.height, int64_t(b.y) + b.height);
  Rect r;
  r.x = int32_t(x0), r.y = int32_t(y0);
  r.width = x1 > x0 ? uint32_t(x1 - x0) : 0;
  r.height = y1 > y0 ? uint32_t(y1 - y0) : 0;
  return r;
}

DrawContext makeContext(const Target& target, const State& st, const Draw& d, const VertexStage& vs,
                        const FragmentStage& fs) {
  DrawContext ctx{};
  ctx.target = &target, ctx.state = &st, ctx.draw = &d, ctx.vertex = &vs, ctx.fragment = &fs;
  ctx.varyingWords = d.varyingCount * 4;
  ctx.samples = target.samples == 4 ? 4 : 1;
  ctx.allSamples = (1u << ctx.samples) - 1;
  // The clip rectangle: render area, scissor 0 and the attachments' extent.
  Rect r = intersect(target.renderArea, st.scissors[0]);
  auto limit = [&](const Surface& s) {
    if (s.base) r = intersect(r, Rect{0, 0, s.width, s.height});
  };
  for (uint32_t i = 0; i < target.colorCount; ++i) limit(target.color[i]);
  if (target.depthStencil.depthFormat != DepthFormat::None) limit(target.depthStencil.depth);
  if (target.depthStencil.stencilFormat != StencilFormat::None) limit(target.depthStencil.stencil);
  r = intersect(r, Rect{0, 0, 1u << 16, 1u << 16});
  ctx.clipX0 = r.x, ctx.clipY0 = r.y;
  ctx.clipX1 = r.x + int32_t(r.width), ctx.clipY1 = r.y + int32_t(r.height);

  bool sampleInputs = false;
  for (uint32_t i = 0; i < fs.inputCount; ++i) {
    sampleInputs = sampleInputs || fs.inputs[i].sample;
    ctx.hasSmooth = ctx.hasSmooth || fs.inputs[i].interpolation == Interpolation::Smooth;
    ctx.hasNoPerspective = ctx.hasNoPerspective || fs.inputs[i].interpolation == Interpolation::NoPerspective;
  }
  ctx.perSample = fs.shade && (st.sampleShading || sampleInputs);
  // Early fragment tests: required by the shader, or equivalent to late ones (nothing the shader does can change
  // the tests' inputs or be observed when the tests fail).
  ctx.earlyTests =
      !fs.shade || fs.earlyFragmentTests ||
      (!fs.writesDepth && !fs.canDiscard && !fs.hasSideEffects && !fs.writesSampleMask && !st.alphaToCoverage);

  const bool depthAttachment =
      target.depthStencil.depthFormat != DepthFormat::None && target.depthStencil.depth.base != nullptr;
  ctx.needsDepth = depthAttachment && (st.depthTest || st.depthBoundsTest);
  ctx.plainFinish = ctx.earlyTests && !fs.writesSampleMask && !st.alphaToCoverage && !st.alphaToOne;
  // Viewport 0 ("Coordinate Transformations").
  const Viewport& vp = st.viewports[0];
  ctx.scaleX = vp.width / 2, ctx.offX = vp.x + vp.width / 2;
  ctx.scaleY = vp.height / 2, ctx.offY = vp.y + vp.height / 2;
  ctx.scaleZ = vp.maxDepth - vp.minDepth, ctx.offZ = vp.minDepth;
  if (st.depthClamp) {
    ctx.depthMin = std::min(vp.minDepth, vp.maxDepth), ctx.depthMax = std::max(vp.minDepth, vp.maxDepth);
  } else {
    ctx.depthMin = 0, ctx.depthMax = 1;
  }
  auto guard = [](float scale, float off) {
    const float room = kGuardPixels - std::fabs(off);
    const float s = std::fabs(scale);
    return s > 0 && room > 0 ? std::min(room / s, 1e30f) : 1.0f;
  };
  ctx.guardX = guard(ctx.scaleX, ctx.offX);
  ctx.guardY = guard(ctx.scaleY, ctx.offY);
  switch (target.depthStencil.depthFormat) {
    case DepthFormat::D16UNorm: ctx.depthR = std::ldexp(1.0, -16); break;
    case DepthFormat::X8D24UNorm: ctx.depthR = std::ldexp(1.0, -24); break;
    default: ctx.depthR = 0; break;
  }
  detail::planBackEnd(ctx);
  return ctx;
}

// Per batch of instances: the shaded vertices and the setup output of each primitive chunk.
struct Batch {
  std::vector<ShadedVertex> vertices;  // every field is written before use (resize keeps old contents)
  std::vector<uint32_t> varyings;
  struct Chunk {
    std::vector<SetupTri> tris;
    std::unique_ptr<detail::Arena> arena;
  };
  std::vector<Chunk> chunks;
  std::vector<uint32_t> tileStart;  // per tile, into tileTris (prefix sums)
  std::vector<const SetupTri*> tileTris;
  std::vector<uint32_t> busyTiles;
};

void shadeVertices(const DrawContext& ctx, const VertexSet& set, uint32_t firstInstance, uint32_t instances, Batch& b) {
  const uint32_t unique = uint32_t(set.vertexIndex.size());
  const size_t total = size_t(unique) * instances;
  b.vertices.resize(total);
  b.varyings.resize(total * ctx.varyingWords);
  for (size_t i = 0; i < total; ++i) {
    ShadedVertex& v = b.vertices[i];
    v.pointSize = 1.0f;
    v.varyings = ctx.varyingWords ? b.varyings.data() + i * ctx.varyingWords : nullptr;
  }
  const uint32_t chunksPerInstance = (unique + kVertexChunk - 1) / kVertexChunk;
  exec::ThreadPool::instance().parallelFor(uint64_t(chunksPerInstance) * instances, [&](uint64_t task,
                                                                                        unsigned worker) {
    const uint32_t inst = uint32_t(task / chunksPerInstance);
    const uint32_t first = uint32_t(task % chunksPerInstance) * kVertexChunk;
    const uint32_t count = std::min(kVertexChunk, unique - first);
    ctx.vertex->shade(ctx.vertex->user, ctx.draw->firstInstance + firstInstance + inst, ctx.viewIndex,
                      set.vertexIndex.data() + first, count, b.vertices.data() + size_t(inst) * unique + first, worker);
  });
}

void setupAll(const DrawContext& ctx, const std::vector<PrimRef>& prims, uint32_t unique, uint32_t instances,
              Batch& b) {
  const uint64_t total = uint64_t(prims.size()) * instances;
  const uint64_t chunkCount = (total + kPrimChunk - 1) / kPrimChunk;
  if (b.chunks.size() < chunkCount) b.chunks.resize(chunkCount);
  exec::ThreadPool::instance().parallelFor(chunkCount, [&](uint64_t chunk, unsigned) {
    Batch::Chunk& out = b.chunks[chunk];
    out.tris.clear();
    out.arena = std::make_unique<detail::Arena>();
    const uint64_t end = std::min(total, (chunk + 1) * kPrimChunk);
    for (uint64_t i = chunk * kPrimChunk; i < end; ++i) {
      const uint64_t inst = i / prims.size();
      const PrimRef& p = prims[i % prims.size()];
      const ShadedVertex* base = b.vertices.data() + inst * unique;
      AssembledPrim a{{base + p.v[0], base + p.v[1], base + p.v[2]}, p.count, p.provoking, p.primitiveId};
      detail::setupPrimitive(ctx, a, out.tris, *out.arena);
    }
  });
  for (uint64_t c = chunkCount; c < b.chunks.size(); ++c) b.chunks[c].tris.clear();
}

// Binning: every triangle goes to the tiles its bounds touch, in draw order (counted, then placed).
void bin(const DrawContext& ctx, Batch& b, int32_t tx0, int32_t ty0, int32_t tilesX, int32_t tilesY) {
  const size_t tiles = size_t(tilesX) * tilesY;
  b.tileStart.assign(tiles + 1, 0);
  auto forTiles = [&](const SetupTri& t, auto&& fn) {
    for (int32_t ty = t.minY / kTileSize - ty0; ty <= t.maxY / kTileSize - ty0; ++ty)
      for (int32_t tx = t.minX / kTileSize - tx0; tx <= t.maxX / kTileSize - tx0; ++tx) fn(size_t(ty) * tilesX + tx);
  };
  for (const Batch::Chunk& c : b.chunks)
    for (const SetupTri& t : c.tris) forTiles(t, [&](size_t tile) { ++b.tileStart[tile + 1]; });
  b.busyTiles.clear();
  for (size_t i = 0; i < tiles; ++i) {
    if (b.tileStart[i + 1]) b.busyTiles.push_back(uint32_t(i));
    b.tileStart[i + 1] += b.tileStart[i];
  }
  b.tileTris.resize(b.tileStart[tiles]);
  std::vector<uint32_t> fill(b.tileStart.begin(), b.tileStart.end() - 1);
  for (const Batch::Chunk& c : b.chunks)
    for (const SetupTri& t : c.tris) forTiles(t, [&](size_t tile) { b.tileTris[fill[tile]++] = &t; });
  (void)ctx;
}

void rasterizeBatch(const DrawContext& ctx, Batch& b, std::vector<detail::WorkerScratch>& scratch) {
  if (ctx.clipX0 >= ctx.clipX1 || ctx.clipY0 >= ctx.clipY1) return;
  const int32_t tx0 = ctx.clipX0 / kTileSize, ty0 = ctx.clipY0 / kTileSize;
  const int32_t tilesX = (ctx.clipX1 - 1) / kTileSize - tx0 + 1, tilesY = (ctx.clipY1 - 1) / kTileSize - ty0 + 1;
  bin(ctx, b, tx0, ty0, tilesX, tilesY);
  struct TileWork {
    const DrawContext* ctx;
    const SetupTri* const* tris;
    size_t count;
    int32_t x, y;
    detail::WorkerScratch* scratch;
    unsigned worker;
    static void run(void* arg) {
      const TileWork& w = *static_cast<const TileWork*>(arg);
      detail::rasterizeTile(*w.ctx, w.tris, w.count, w.x, w.y, *w.scratch, w.worker);
    }
  };
  const FragmentStage& fs = *ctx.fragment;
  exec::ThreadPool::instance().parallelFor(b.busyTiles.size(), [&](uint64_t i, unsigned worker) {
    const uint32_t tile = b.busyTiles[i];
    const int32_t tx = int32_t(tile % tilesX) + tx0, ty = int32_t(tile / tilesX) + ty0;
    TileWork w{&ctx,
               b.tileTris.data() + b.tileStart[tile],
               b.tileStart[tile + 1] - b.tileStart[tile],
               tx * kTileSize,
               ty * kTileSize,
               &scratch[worker],
               worker};
    if (fs.runTile) {
      fs.runTile(fs.user, TileWork::run, &w, worker);
    } else {
      TileWork::run(&w);
    }
  });
}

}  // namespace

void draw(const Target& target, const State& state, const Draw& d, const VertexStage& vertex,
          const FragmentStage& fragment) {
  if (d.count == 0 || d.instanceCount == 0 || !vertex.shade) return;
  const VertexSet set = uniqueVertices(state, d);
  const uint32_t unique = uint32_t(set.vertexIndex.size());
  if (unique == 0) return;
  const std::vector<PrimRef> prims = assemble(state, set.slots);
  DrawContext ctx = makeContext(target, state, d, vertex, fragment);
  // Storage kept by the calling thread from draw to draw (no page faults or clearing per draw); a draw that grew
  // it past kKeepBytes gives it back at its end.
  thread_local std::vector<detail::WorkerScratch> scratch;
  thread_local Batch batch;
  if (scratch.size() < exec::ThreadPool::instance().workerSlots())
    scratch.resize(exec::ThreadPool::instance().workerSlots());
  const uint32_t perBatch = uint32_t(std::clamp<uint64_t>(kBatchVertices / unique, 1, d.instanceCount));
  const uint32_t views = target.viewMask ? target.viewMask : 1;
  for (uint32_t vm = views; vm; vm &= vm - 1) {
    // Multiview: the draw once per view, each into the layer of its index.
    ctx.viewIndex = target.viewMask ? uint32_t(std::countr_zero(vm)) : 0;
    ctx.layer = ctx.viewIndex;
    for (uint32_t inst = 0; inst < d.instanceCount; inst += perBatch) {
      const uint32_t n = std::min(perBatch, d.instanceCount - inst);
      shadeVertices(ctx, set, inst, n, batch);
      if (state.rasterizerDiscard || prims.empty()) continue;
      setupAll(ctx, prims, unique, n, batch);
      rasterizeBatch(ctx, batch, scratch);
    }
  }
  if (batch.vertices.capacity() * sizeof(ShadedVertex) + batch.varyings.capacity() * 4 > kKeepBytes) batch = Batch();
}

}  // namespace vkrt::raster
