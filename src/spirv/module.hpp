// A read-only view of a SPIR-V module: instructions (with their word offsets), result ids, types, constants,
// decorations, names, entry points and execution modes. No LLVM here: this header is included by the runtime.
//
// The reader assumes the module passed SPIRV-Tools' validator (vkCreateShaderModule guarantees it), but never
// reads past the end of the words even when it did not: parse() returns false with a message instead.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#ifndef SPV_ENABLE_UTILITY_CODE
#define SPV_ENABLE_UTILITY_CODE
#endif
#include <spirv/unified1/spirv.hpp>

namespace vkrt::spirv {

struct Instruction {
  spv::Op op;
  uint32_t offset;  // word offset of the instruction within the module
  uint32_t count;   // words, opcode word included
  const uint32_t* words;

  uint32_t word(uint32_t i) const { return i < count ? words[i] : 0; }
  // A literal string starting at word `i` (nul-terminated, padded to words).
  std::string string(uint32_t i, uint32_t* wordsUsed = nullptr) const;
};

struct Type {
  enum Kind { Void, Bool, Int, Float, Vector, Matrix, Array, RuntimeArray, Struct, Pointer, Function, Opaque };
  Kind kind = Opaque;
  uint32_t width = 0;     // Int, Float: bits
  bool isSigned = false;  // Int
  uint32_t element = 0;   // Vector: component; Matrix: column type; Array/RuntimeArray: element; Pointer: pointee
                          // Function: return type
  uint32_t count = 0;     // Vector: components; Matrix: columns; Array: length (from its constant)
  std::vector<uint32_t> members;                     // Struct: member types; Function: parameter types
  spv::StorageClass storage = spv::StorageClassMax;  // Pointer
};

struct Decorations {
  int32_t builtIn = -1;
  int32_t set = -1;
  int32_t binding = -1;
  int32_t offset = -1;
  int32_t arrayStride = -1;
  int32_t matrixStride = -1;
  int32_t specId = -1;
  int32_t fpRoundingMode = -1;  // FPRoundingMode (spv::FPRoundingMode) of a conversion's result
  int32_t location = -1;
  int32_t component = -1;  // Component (user Input/Output variables and block members)
  int32_t index = -1;      // Index (fragment outputs: 1 for the second source of dual-source blending)
  bool flat = false;       // the interpolation decorations of fragment inputs
  bool noPerspective = false;
  bool centroid = false;
  bool sample = false;
  bool rowMajor = false;
  bool block = false;
  bool bufferBlock = false;
};

struct Constant {
  uint32_t type = 0;
  bool composite = false;
  bool spec = false;               // from an OpSpecConstant* instruction
  std::vector<uint32_t> words;     // scalar: the value's words (bool: one word 0 or 1)
  std::vector<uint32_t> elements;  // composite: constituent ids
  bool null = false;               // OpConstantNull
};

struct EntryPoint {
  spv::ExecutionModel model;
  uint32_t function = 0;
  std::string name;
  std::vector<uint32_t> interface;
  uint32_t localSize[3] = {1, 1, 1};
  uint32_t localSizeId[3] = {0, 0, 0};  // LocalSizeId: constant ids (0 when LocalSize was used)
  std::vector<uint32_t> modes;          // every execution mode declared for it (spv::ExecutionMode)
};

class Module {
 public:
  // Parses `words`; on failure returns false and sets `error`. The words must outlive the Module.
  bool parse(const uint32_t* words, size_t wordCount, std::string* error);

  std::vector<Instruction> instructions;
  std::unordered_map<uint32_t, uint32_t> defs;  // result id -> index in `instructions`
  std::unordered_map<uint32_t, Type> types;
  std::unordered_map<uint32_t, Constant> constants;
  std::unordered_map<uint32_t, Decorations> decorations;
  std::unordered_map<uint32_t, std::vector<Decorations>> memberDecorations;
  std::unordered_map<uint32_t, std::string> names;
  std::vector<EntryPoint> entryPoints;
  std::vector<spv::Capability> capabilities;
  std::unordered_map<uint32_t, std::string> extInstImports;  // id -> set name
  uint32_t bound = 0;
  uint32_t version = 0;

  const Instruction* def(uint32_t id) const;
  const Type* type(uint32_t id) const;
  const Constant* constant(uint32_t id) const;
  const Decorations& decor(uint32_t id) const;
  const Decorations& memberDecor(uint32_t structId, uint32_t member) const;
  // The entry point with this name and model, or nullptr.
  const EntryPoint* findEntryPoint(const char* name, spv::ExecutionModel model) const;
  // A scalar integer constant's value (zero-extended), or false when `id` is not one.
  bool constantU64(uint32_t id, uint64_t* value) const;
  // Whether `id` is computed by an OpSpecConstantOp (its value is known only after folding).
  bool specConstantOp(uint32_t id) const;
  // The result type of the instruction defining `id` (0 when it has none).
  uint32_t typeOf(uint32_t id) const;
};

// One specialization: the constant's SpecId and its bytes (VkSpecializationMapEntry's size: 1, 2, 4 or 8).
struct SpecValue {
  uint32_t specId;
  std::vector<uint8_t> bytes;
};

// Rewrites the OpSpecConstant/OpSpecConstantTrue/OpSpecConstantFalse instructions whose SpecId appears in
// `values` so that their default is the given value (the words are copied; the module stays valid SPIR-V).
// Returns false with `error` set when a value's size does not match its constant's type.
bool applySpecialization(std::vector<uint32_t>& words, const std::vector<SpecValue>& values, std::string* error);

// "OpIAdd" etc. (SPIRV-Tools' opcode table).
std::string opName(spv::Op op);

// Combined counter adds (abi::PendingAdds): the parts of the rule that Codegen::combinableAdd and
// hasCombinableAdds (below) share.
// OpAtomicIAdd, OpAtomicISub, OpAtomicIIncrement, OpAtomicIDecrement.
bool combinableAddOp(spv::Op op);
// Relaxed: no ordering, availability, visibility or volatile bits.
bool relaxedSemantics(uint64_t semantics);
// Every word of the module's function bodies (from the first OpFunction on, opcodes aside) by its occurrences: a
// result id counted once is named by no instruction but its definition.
void countBodyWords(const Module& m, std::unordered_map<uint32_t, uint32_t>& counts);
// Whether the module has an add Codegen may combine: one of combinableAddOp's with constant relaxed semantics and a
// result no instruction of a function body names (whatever its pointer: a superset of what is combined). What a
// pipeline decides CompileRequest::combineAdds by; false for words that do not parse.
bool hasCombinableAdds(const uint32_t* words, size_t wordCount);

}  // namespace vkrt::spirv
