// Private to src/spirv: the structured control flow graph of a function and which of its values vary across the
// lanes of an SPMD batch (spmd.cpp). No LLVM here.
//
// A value is uniform when every lane of a batch computes the same one: constants, push constant, uniform and
// storage buffer loads at uniform addresses, WorkgroupId, NumWorkgroups, and what is computed from those alone. The
// invocation ids vary (LocalInvocationId.y and .z, and the same components of GlobalInvocationId, stay uniform when a
// batch never crosses a row, resp. a slice, of the workgroup: the batches are consecutive local indices starting at
// multiples of the lane count). Control flow makes values vary too: a branch on a varying condition is divergent,
// and so is every loop that contains one (its lanes may leave in different iterations); a phi at the merge of a
// divergent selection or in a divergent loop's header varies, and a Function variable stored under divergent
// control (or with a varying value, or through a varying index) needs storage per lane.
#pragma once

#include <cstdint>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "spirv/module.hpp"

namespace vkrt::spirv {

struct Cfg {
  struct Block {
    uint32_t label = 0;
    size_t first = 0;                        // index of OpLabel in the module's instructions
    size_t last = 0;                         // index of the terminator
    uint32_t merge = 0, continueTarget = 0;  // OpSelectionMerge / OpLoopMerge
    bool loop = false;                       // the header of a loop
    std::vector<uint32_t> successors;
  };
  std::vector<Block> blocks;                                              // in the function's order
  std::unordered_map<uint32_t, size_t> index;                             // label -> position in `blocks`
  std::unordered_map<uint32_t, std::unordered_set<uint32_t>> loopBlocks;  // loop header -> its construct's blocks
  std::unordered_map<uint32_t, uint32_t> blockOf;                         // result id -> label of the block defining it
  size_t functionEnd = 0;                                                 // index of OpFunctionEnd

  // Builds the graph of the function starting at instruction `first` (OpFunction). False with `why` when the
  // function is not one the SPMD path handles (OpSwitch, a block without terminator...).
  bool build(const Module& m, size_t first, std::string* why);
  // The loops whose construct holds `label`, innermost last.
  std::vector<uint32_t> loopsOf(uint32_t label) const;
};

struct Uniformity {
  // Bit c set: component c of the value (or the pointer, as one bit) varies. Ids not listed are uniform.
  std::unordered_map<uint32_t, uint32_t> varying;
  // Function variables that need storage per lane; a fragment shader's Input, Output and Private variables are
  // listed before analyze() (every lane has its own).
  std::unordered_set<uint32_t> laneVariables;
  std::unordered_set<uint32_t> divergentLoops;
  std::unordered_set<uint32_t> divergentBlocks;  // blocks under divergent control
  std::unordered_set<uint32_t> divergentMerges;  // merges of divergent selections and loops

  // `localSize` and `lanes` give the batch shape (see above).
  bool analyze(const Module& m, const Cfg& cfg, const uint32_t localSize[3], unsigned lanes, std::string* why);
  // The values defined in `loop` and used after it (not by phis): each lane keeps the value it had when it left.
  static std::vector<uint32_t> liveOuts(const Module& m, const Cfg& cfg, uint32_t loop);
  uint32_t bits(uint32_t id) const {
    auto it = varying.find(id);
    return it == varying.end() ? 0 : it->second;
  }
};

}  // namespace vkrt::spirv
