// The structured control flow graph of a function and the uniformity analysis of the SPMD path (uniformity.hpp).
#include "spirv/uniformity.hpp"

#include "spirv/opcode_support.hpp"

#include <algorithm>

namespace vkrt::spirv {

bool Cfg::build(const Module& m, size_t first, std::string* why) {
  const auto& ins = m.instructions;
  Block* cur = nullptr;
  for (size_t i = first + 1; i < ins.size(); ++i) {
    const Instruction& in = ins[i];
    if (in.op == spv::OpFunctionEnd) {
      functionEnd = i;
      break;
    }
    switch (in.op) {
      case spv::OpLabel:
        blocks.push_back({});
        cur = &blocks.back();
        cur->label = in.word(1);
        cur->first = i;
        index[cur->label] = blocks.size() - 1;
        continue;
      case spv::OpSelectionMerge:
        if (cur) cur->merge = in.word(1);
        continue;
      case spv::OpLoopMerge:
        if (cur) {
          cur->merge = in.word(1);
          cur->continueTarget = in.word(2);
          cur->loop = true;
        }
        continue;
      case spv::OpBranch:
      case spv::OpBranchConditional:
      case spv::OpReturn:
      case spv::OpReturnValue:
      case spv::OpUnreachable:
        if (!cur) break;
        cur->last = i;
        if (in.op == spv::OpBranch) cur->successors = {in.word(1)};
        if (in.op == spv::OpBranchConditional) cur->successors = {in.word(2), in.word(3)};
        cur = nullptr;
        continue;
      case spv::OpSwitch: {
        if (!cur) break;
        cur->last = i;
        cur->successors = {in.word(2)};
        uint32_t width = 1;
        if (const Type* t = m.type(m.typeOf(in.word(1)))) width = t->width > 32 ? 2 : 1;
        for (uint32_t w = 3; w + width < in.count; w += width + 1) cur->successors.push_back(in.word(w + width));
        cur = nullptr;
        continue;
      }
      case spv::OpKill:
      case spv::OpTerminateInvocation:  // fragment shaders: the lanes leave, as with OpReturn
        if (!cur) break;
        cur->last = i;
        cur = nullptr;
        continue;
      default: break;
    }
    if (!cur && in.op != spv::OpFunctionParameter) {
      *why = "an instruction outside a block";
      return false;
    }
    if (cur && in.count >= 3) {
      auto d = m.defs.find(in.word(2));
      if (d != m.defs.end() && d->second == i) blockOf[in.word(2)] = cur->label;  // a result id (not an operand)
    }
  }
  if (!functionEnd || blocks.empty()) {
    *why = "a function without blocks";
    return false;
  }
  for (const Block& b : blocks) {
    if (!b.last) {
      *why = "a block without a terminator";
      return false;
    }
    for (uint32_t s : b.successors)
      if (!index.count(s)) {
        *why = "a branch to an unknown block";
        return false;
      }
  }
  // A loop's construct: the blocks reachable from its header without passing its merge.
  for (const Block& h : blocks) {
    if (!h.loop) continue;
    auto& set = loopBlocks[h.label];
    std::vector<uint32_t> work = {h.label};
    while (!work.empty()) {
      uint32_t l = work.back();
      work.pop_back();
      if (l == h.merge || !set.insert(l).second) continue;
      for (uint32_t s : blocks[index[l]].successors) work.push_back(s);
    }
  }
  return true;
}

std::vector<uint32_t> Cfg::loopsOf(uint32_t label) const {
  std::vector<std::pair<size_t, uint32_t>> found;
  for (const auto& [header, set] : loopBlocks)
    if (set.count(label)) found.push_back({set.size(), header});
  std::sort(found.begin(), found.end(), [](auto& a, auto& b) { return a.first > b.first; });  // outermost first
  std::vector<uint32_t> r;
  for (auto& f : found) r.push_back(f.second);
  return r;
}

std::vector<uint32_t> Uniformity::liveOuts(const Module& m, const Cfg& cfg, uint32_t loop) {
  // A phi takes a value on an edge that leaves the loop per lane, as the edge is taken: that use is not listed; a
  // phi's value coming by an edge from outside the loop (after it) is a use like any other.
  std::vector<uint32_t> out;
  std::unordered_set<uint32_t> seen;
  const auto& inLoop = cfg.loopBlocks.at(loop);
  auto use = [&](uint32_t id) {
    auto it = cfg.blockOf.find(id);
    if (it != cfg.blockOf.end() && inLoop.count(it->second) && m.def(id)->op != spv::OpVariable &&
        seen.insert(id).second)
      out.push_back(id);
  };
  for (const Cfg::Block& blk : cfg.blocks) {
    if (inLoop.count(blk.label)) continue;
    for (size_t i = blk.first + 1; i <= blk.last; ++i) {
      const Instruction& in = m.instructions[i];
      // (OpLine's words are a file and literals: a line number is no use of the id it happens to equal.)
      if (in.op == spv::OpLine) continue;
      if (in.op == spv::OpPhi) {
        for (uint32_t w = 3; w + 1 < in.count; w += 2)
          if (!inLoop.count(in.word(w + 1))) use(in.word(w));
        continue;
      }
      for (uint32_t w = 1; w < in.count; ++w) use(in.words[w]);
    }
  }
  return out;
}

namespace {

uint32_t full(uint32_t n) { return n >= 32 ? ~0u : (1u << n) - 1; }

}  // namespace

bool Uniformity::analyze(const Module& m, const Cfg& cfg, const uint32_t localSize[3], unsigned lanes,
                         std::string* why) {
  auto count = [&](uint32_t typeId) -> uint32_t {
    const Type* t = m.type(typeId);
    return t && t->kind == Type::Vector ? t->count : 1;
  };
  // The Function variable or module variable a pointer derives from, and a built-in vector component.
  std::unordered_map<uint32_t, uint32_t> root;
  auto rootOf = [&](uint32_t p) {
    auto it = root.find(p);
    return it == root.end() ? p : it->second;
  };
  auto storageOf = [&](uint32_t var) {
    const Instruction* d = m.def(var);
    return d && d->op == spv::OpVariable ? spv::StorageClass(d->word(3)) : spv::StorageClassMax;
  };
  auto builtInBits = [&](int builtIn) -> uint32_t {
    switch (builtIn) {
      case spv::BuiltInGlobalInvocationId:
      case spv::BuiltInLocalInvocationId:
      case spv::BuiltInLaunchIdKHR:  // ray generation: localSize is the batch's row (spmd.cpp)
        return 1u | (localSize[0] % lanes ? 2u : 0u) | ((localSize[0] * localSize[1]) % lanes ? 4u : 0u);
      case spv::BuiltInLocalInvocationIndex: return 1u;
      default: return 0u;
    }
  };
  auto set = [&](uint32_t id, uint32_t bits, bool& changed) {
    if (!bits) return;
    uint32_t& v = varying[id];
    if ((v | bits) != v) {
      v |= bits;
      changed = true;
    }
  };
  // Where a walk from a block stops in the loops around it: their headers, merges and continue targets.
  auto loopStops = [&](const std::vector<uint32_t>& loops) {
    std::unordered_set<uint32_t> stops;
    for (uint32_t l : loops) {
      const Cfg::Block& h = cfg.blocks[cfg.index.at(l)];
      stops.insert({h.label, h.merge, h.continueTarget});
    }
    return stops;
  };
  // Each selection construct's blocks (a selection or switch header's: reachable from it before its merge, and
  // before the headers, merges and continue targets of the loops around it), and so the merges of the selection
  // constructs around each block: where lanes that leave a construct early (a break out of a switch) meet again.
  std::unordered_map<uint32_t, std::vector<uint32_t>> enclosingMerges;  // block -> merges, any order
  for (const Cfg::Block& h : cfg.blocks) {
    if (h.loop || !h.merge) continue;
    std::unordered_set<uint32_t> stops = loopStops(cfg.loopsOf(h.label));
    stops.insert(h.merge);
    std::vector<uint32_t> work(h.successors.begin(), h.successors.end());
    std::unordered_set<uint32_t> seen;
    while (!work.empty()) {
      uint32_t l = work.back();
      work.pop_back();
      if (stops.count(l) || !seen.insert(l).second) continue;
      enclosingMerges[l].push_back(h.merge);
      for (uint32_t x : cfg.blocks[cfg.index.at(l)].successors) work.push_back(x);
    }
  }
  bool changed = true;
  while (changed) {
    changed = false;
    for (const Cfg::Block& blk : cfg.blocks) {
      bool divergent = divergentBlocks.count(blk.label) != 0;
      for (size_t i = blk.first + 1; i <= blk.last; ++i) {
        const Instruction& in = m.instructions[i];
        uint32_t n = in.count >= 3 ? count(in.word(1)) : 1;
        switch (in.op) {
          case spv::OpVariable:
          case spv::OpLine:
          case spv::OpNoLine:
          case spv::OpNop:
          case spv::OpSelectionMerge:
          case spv::OpLoopMerge:
          case spv::OpBranch:
          case spv::OpBranchConditional:
          case spv::OpReturn:
          case spv::OpReturnValue:
          case spv::OpUnreachable:
          case spv::OpKill:
          case spv::OpTerminateInvocation:
          case spv::OpDemoteToHelperInvocation: break;
          case spv::OpIsHelperInvocationEXT: set(in.word(2), 1, changed); break;  // demotion makes it vary
          case spv::OpStore: {
            uint32_t var = rootOf(in.word(1));
            if (storageOf(var) == spv::StorageClassFunction && (bits(in.word(2)) || bits(in.word(1)) || divergent) &&
                laneVariables.insert(var).second)
              changed = true;
            break;
          }
          case spv::OpAccessChain:
          case spv::OpInBoundsAccessChain: {
            uint32_t base = in.word(3);
            root[in.word(2)] = rootOf(base);
            uint32_t b = bits(base) ? 1 : 0;
            for (uint32_t w = 4; w < in.count; ++w) b |= bits(in.word(w)) ? 1 : 0;
            // A component of a built-in vector: that component's uniformity.
            const Instruction* var = m.def(rootOf(base));
            if (!b && var && storageOf(var->word(2)) == spv::StorageClassInput && base == var->word(2) &&
                in.count == 5) {
              uint64_t c = 0;
              if (m.constantU64(in.word(4), &c) && c < 32) b = (builtInBits(m.decor(base).builtIn) >> c) & 1;
            } else if (!b && var && storageOf(var->word(2)) == spv::StorageClassInput) {
              b = builtInBits(m.decor(var->word(2)).builtIn) ? 1 : 0;
            }
            set(in.word(2), b, changed);
            break;
          }
          case spv::OpLoad: {
            uint32_t p = in.word(3);
            uint32_t var = rootOf(p);
            uint32_t b = 0;
            if (laneVariables.count(var)) {
              b = full(n);
            } else if (p == var && storageOf(var) == spv::StorageClassInput) {
              b = builtInBits(m.decor(var).builtIn) & full(n);
            } else if (bits(p)) {
              b = full(n);
            }
            set(in.word(2), b, changed);
            break;
          }
          case spv::OpPhi: {
            uint32_t b = divergentMerges.count(blk.label) ? full(n) : 0;
            for (uint32_t w = 3; w + 1 < in.count; w += 2) b |= bits(in.word(w));
            set(in.word(2), b ? full(n) : 0, changed);
            break;
          }
          case spv::OpCompositeExtract: {
            uint32_t src = bits(in.word(3));
            const Type* t = m.type(m.typeOf(in.word(3)));
            uint32_t b = t && t->kind == Type::Vector && in.count == 5 ? (src >> in.word(4)) & 1 : (src ? full(n) : 0);
            set(in.word(2), b, changed);
            break;
          }
          case spv::OpCompositeInsert: {
            const Type* t = m.type(in.word(1));
            uint32_t b;
            if (t && t->kind == Type::Vector && in.count == 6)
              b = (bits(in.word(4)) & ~(1u << in.word(5))) | ((bits(in.word(3)) & 1) << in.word(5));
            else
              b = bits(in.word(3)) || bits(in.word(4)) ? full(n) : 0;
            set(in.word(2), b, changed);
            break;
          }
          case spv::OpCompositeConstruct: {
            const Type* t = m.type(in.word(1));
            uint32_t b = 0, at = 0;
            bool vec = t && t->kind == Type::Vector;
            for (uint32_t w = 3; w < in.count; ++w) {
              uint32_t k = count(m.typeOf(in.word(w)));
              if (vec)
                b |= (bits(in.word(w)) & full(k)) << at;
              else if (bits(in.word(w)))
                b = full(n);
              at += k;
            }
            set(in.word(2), b & full(n), changed);
            break;
          }
          case spv::OpImageRead:
          case spv::OpImageFetch:
          case spv::OpImageSampleImplicitLod:
          case spv::OpImageSampleExplicitLod:
          case spv::OpImageSampleDrefImplicitLod:
          case spv::OpImageSampleDrefExplicitLod:
          case spv::OpImageGather:
          case spv::OpImageDrefGather: {
            // A texel varies with any of its operands, whatever their widths (the image operands' mask, a literal,
            // follows the coordinate and the Dref or component operand).
            const bool extra = in.op == spv::OpImageSampleDrefImplicitLod ||
                               in.op == spv::OpImageSampleDrefExplicitLod || in.op == spv::OpImageGather ||
                               in.op == spv::OpImageDrefGather;
            const uint32_t maskAt = extra ? 6 : 5;
            uint32_t b = 0;
            for (uint32_t w = 3; w < in.count; ++w) b |= w == maskAt ? 0 : bits(in.word(w));
            set(in.word(2), b ? full(n) : 0, changed);
            break;
          }
          case spv::OpVectorShuffle: {
            uint32_t n1 = count(m.typeOf(in.word(3)));
            uint32_t b1 = bits(in.word(3)), b2 = bits(in.word(4)), b = 0;
            for (uint32_t w = 5; w < in.count; ++w) {
              uint32_t k = in.word(w);
              uint32_t v = k == 0xffffffffu ? 0 : k < n1 ? (b1 >> k) & 1 : (b2 >> (k - n1)) & 1;
              b |= v << (w - 5);
            }
            set(in.word(2), b, changed);
            break;
          }
          default: {
            // An atomic's value varies whatever its operands: each lane's runs after the lanes before it.
            if (atomicOp(in.op)) {
              if (in.op != spv::OpAtomicStore) set(in.word(2), full(n), changed);
              break;
            }
            // Component-wise where the operands are as wide as the result (a scalar operand counts for every
            // component), else all or nothing. (Instructions without a result, OpLine's literals or
            // OpImageWrite's coordinate in word 2, mark nothing.)
            bool result = false, type = false;
            spv::HasResultAndType(in.op, &result, &type);
            if (in.count < 3 || !result || !type) break;
            uint32_t firstOperand = in.op == spv::OpExtInst ? 5 : 3;
            // GLSL.std.450's functions of whole vectors (normalize, cross, reflect, ...) and products with a matrix mix
            // the components.
            const bool mixes =
                (in.op == spv::OpExtInst && in.count > 4 && glslSupport(in.word(4)).spmd == SpmdForm::Own) ||
                in.op == spv::OpMatrixTimesVector || in.op == spv::OpVectorTimesMatrix;
            uint32_t b = 0;
            for (uint32_t w = firstOperand; w < in.count; ++w) {
              uint32_t ob = bits(in.word(w));
              if (!ob) continue;
              uint32_t k = count(m.typeOf(in.word(w)));
              b |= k == n && !mixes ? ob : full(n);
            }
            set(in.word(2), b, changed);
            break;
          }
        }
      }
    }
    // A value made in a divergent loop and used after it holds, per lane, what it was when the lane left.
    for (uint32_t l : divergentLoops)
      for (uint32_t id : liveOuts(m, cfg, l)) set(id, full(count(m.typeOf(id))), changed);
    // Divergence from the branches on varying conditions.
    for (const Cfg::Block& blk : cfg.blocks) {
      const Instruction& term = m.instructions[blk.last];
      if ((term.op != spv::OpBranchConditional && term.op != spv::OpSwitch) || !bits(term.word(1))) continue;
      std::vector<uint32_t> loops = cfg.loopsOf(blk.label);
      const std::unordered_set<uint32_t> stops = loopStops(loops);
      // The loops the lanes may leave apart (from `leaves` on, innermost last: loops[leaves..]), which become
      // divergent. A loop's own exit test (a header's or continue construct's conditional branch) leaves the innermost
      // loop only (structured breaks leave only it). A selection construct leaves the loops whose merge a path of it
      // reaches (the innermost of them and those inside it), and every loop where a path returns or kills; where
      // every path stays in the loops, its divergence ends at its merge and the loops' header values stay uniform
      // where their operands are. The blocks a path reaches before the merge run under divergent control, and lanes
      // may come to them by different edges: their phis vary (also at a continue target that a `continue` reaches).
      // A path that leaves the construct for an enclosing one's merge (a break out of a switch: the inliner's early
      // returns) rejoins the lanes that took the merge further on: then what follows the merge in the loop iteration
      // is divergent too.
      // (A conditional branch without a merge of its own whose target is an enclosing construct's merge, a break out
      // of it, is walked the same way; one to a loop's merge, header or continue target is that loop's exit test.)
      bool breaksOut = false;
      if (auto e = enclosingMerges.find(blk.label); e != enclosingMerges.end() && !blk.merge)
        for (uint32_t t : blk.successors)
          breaksOut = breaksOut || std::find(e->second.begin(), e->second.end(), t) != e->second.end();
      size_t leaves = loops.size();
      if ((blk.loop || (!blk.merge && !breaksOut)) && !loops.empty()) leaves = loops.size() - 1;
      if (!blk.loop && (blk.merge || breaksOut)) {
        if (blk.merge && divergentMerges.insert(blk.merge).second) changed = true;
        // A path that reaches the merge of a construct around this one (`outer`) ends there: the lanes meet there.
        std::unordered_set<uint32_t> outer, reached;
        if (auto e = enclosingMerges.find(blk.label); e != enclosingMerges.end())
          outer.insert(e->second.begin(), e->second.end());
        auto walk = [&](std::vector<uint32_t> work, std::unordered_set<uint32_t>& seen, bool mark) {
          while (!work.empty()) {
            uint32_t l = work.back();
            work.pop_back();
            if (l == blk.merge || !seen.insert(l).second) continue;
            if (outer.count(l)) {
              reached.insert(l);
              if (mark && divergentMerges.insert(l).second) changed = true;
              continue;
            }
            if (stops.count(l)) {
              for (size_t k = 0; k < loops.size(); ++k) {
                const Cfg::Block& h = cfg.blocks[cfg.index.at(loops[k])];
                if (l == h.merge) leaves = std::min(leaves, k);
                if (mark && (l == h.label || l == h.continueTarget) && divergentMerges.insert(l).second) changed = true;
              }
              continue;
            }
            const Cfg::Block& lb = cfg.blocks[cfg.index.at(l)];
            if (mark) {
              // (A loop's header inside the region is entered by the active lanes together: its phis vary as their
              // operands do.)
              if (divergentBlocks.insert(l).second) changed = true;
              if (!lb.loop && divergentMerges.insert(l).second) changed = true;
              const spv::Op end = m.instructions[lb.last].op;
              if (end != spv::OpBranch && end != spv::OpBranchConditional && end != spv::OpSwitch) leaves = 0;
            }
            for (uint32_t s : lb.successors) work.push_back(s);
          }
        };
        std::unordered_set<uint32_t> inside;
        walk(std::vector<uint32_t>(blk.successors.begin(), blk.successors.end()), inside, true);
        if (blk.merge && !reached.empty()) {
          // Lanes left for an outer merge: those that took this merge run on alone until they meet them there.
          outer = reached;
          std::unordered_set<uint32_t> again;
          if (divergentBlocks.insert(blk.merge).second) changed = true;
          walk(std::vector<uint32_t>(cfg.blocks[cfg.index.at(blk.merge)].successors.begin(),
                                     cfg.blocks[cfg.index.at(blk.merge)].successors.end()),
               again, true);
        }
      }
      for (size_t k = leaves; k < loops.size(); ++k) {
        const uint32_t l = loops[k];
        const Cfg::Block& h = cfg.blocks[cfg.index.at(l)];
        // (Its header's phis stay as their operands make them: the lanes that come back all come from the same
        // iteration; those that left keep their values as live-outs.)
        if (divergentLoops.insert(l).second) changed = true;
        if (divergentMerges.insert(h.merge).second) changed = true;
        for (uint32_t b : cfg.loopBlocks.at(l))
          if (divergentBlocks.insert(b).second) changed = true;
      }
    }
  }
  return true;
}

}  // namespace vkrt::spirv
