#include "spirv/module.hpp"
#include "spirv/newer_tokens.hpp"

#include <cstdio>
#include <cstring>

// SPIRV-Tools' opcode name table (part of the static library vkrt links; not in its public headers).
const char* spvOpcodeString(spv::Op opcode);

namespace vkrt::spirv {

std::string opName(spv::Op op) { return std::string("Op") + spvOpcodeString(op); }

std::string Instruction::string(uint32_t i, uint32_t* wordsUsed) const {
  std::string s;
  uint32_t w = i;
  for (; w < count; ++w) {
    uint32_t v = words[w];
    bool end = false;
    for (int b = 0; b < 4; ++b) {
      char c = char((v >> (8 * b)) & 0xff);
      if (!c) {
        end = true;
        break;
      }
      s.push_back(c);
    }
    if (end) {
      ++w;
      break;
    }
  }
  if (wordsUsed) *wordsUsed = w - i;
  return s;
}

namespace {

void setDecoration(Decorations& d, const Instruction& in, uint32_t first) {
  uint32_t kind = in.word(first);
  uint32_t arg = in.word(first + 1);
  switch (kind) {
    case spv::DecorationBuiltIn: d.builtIn = int32_t(arg); break;
    case spv::DecorationDescriptorSet: d.set = int32_t(arg); break;
    case spv::DecorationBinding: d.binding = int32_t(arg); break;
    case spv::DecorationOffset: d.offset = int32_t(arg); break;
    case spv::DecorationArrayStride: d.arrayStride = int32_t(arg); break;
    case spv::DecorationMatrixStride: d.matrixStride = int32_t(arg); break;
    case spv::DecorationSpecId: d.specId = int32_t(arg); break;
    case spv::DecorationLocation: d.location = int32_t(arg); break;
    case spv::DecorationRowMajor: d.rowMajor = true; break;
    case spv::DecorationBlock: d.block = true; break;
    case spv::DecorationBufferBlock: d.bufferBlock = true; break;
    case spv::DecorationFPRoundingMode: d.fpRoundingMode = int32_t(arg); break;
    case spv::DecorationComponent: d.component = int32_t(arg); break;
    case spv::DecorationIndex: d.index = int32_t(arg); break;
    case spv::DecorationFlat: d.flat = true; break;
    case spv::DecorationNoPerspective: d.noPerspective = true; break;
    case spv::DecorationCentroid: d.centroid = true; break;
    case spv::DecorationSample: d.sample = true; break;
    default: break;
  }
}

bool hasResult(spv::Op op, bool* hasType) {
  bool r = false, t = false;
  spv::HasResultAndType(op, &r, &t);
  if (uint32_t(op) == kOpRayQueryGetIntersectionTriangleVertexPositionsKHR) r = t = true;  // newer than spirv.hpp
  *hasType = t;
  return r;
}

}  // namespace

bool Module::parse(const uint32_t* words, size_t wordCount, std::string* error) {
  auto fail = [&](uint32_t at, const char* what) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "malformed SPIR-V at word %u: %s", at, what);
    *error = buf;
    return false;
  };
  if (wordCount < 5 || words[0] != spv::MagicNumber) return fail(0, "no SPIR-V header");
  version = words[1];
  bound = words[3];
  for (size_t pos = 5; pos < wordCount;) {
    uint32_t count = words[pos] >> 16;
    if (count == 0 || pos + count > wordCount) return fail(uint32_t(pos), "instruction word count out of range");
    Instruction in{spv::Op(words[pos] & 0xffff), uint32_t(pos), count, words + pos};
    bool hasType = false;
    if (hasResult(in.op, &hasType)) {
      uint32_t id = in.word(hasType ? 2 : 1);
      if (id == 0 || id >= bound) return fail(in.offset, "result id out of range");
      defs[id] = uint32_t(instructions.size());
    }
    instructions.push_back(in);
    pos += count;
  }

  for (const Instruction& in : instructions) {
    auto need = [&](uint32_t n) { return in.count >= n; };
    // SPIR-V's enumerants are below 2^31 (spirv.hpp's enums end at ...Max = 0x7fffffff, so that is also what the
    // C++ enums can hold): a larger word where the reader keeps an enumerant is not SPIR-V.
    auto enumerant = [&](uint32_t i) { return in.word(i) <= 0x7fffffffu; };
    switch (in.op) {
      case spv::OpCapability:
        if (!enumerant(1)) return fail(in.offset, "OpCapability operand out of range");
        if (need(2)) capabilities.push_back(spv::Capability(in.word(1)));
        break;
      case spv::OpExtInstImport:
        if (need(3)) extInstImports[in.word(1)] = in.string(2);
        break;
      case spv::OpName:
        if (need(3)) names[in.word(1)] = in.string(2);
        break;
      case spv::OpEntryPoint: {
        if (!need(4)) return fail(in.offset, "short OpEntryPoint");
        if (!enumerant(1)) return fail(in.offset, "OpEntryPoint execution model out of range");
        EntryPoint ep;
        ep.model = spv::ExecutionModel(in.word(1));
        ep.function = in.word(2);
        uint32_t used = 0;
        ep.name = in.string(3, &used);
        for (uint32_t i = 3 + used; i < in.count; ++i) ep.interface.push_back(in.word(i));
        entryPoints.push_back(std::move(ep));
        break;
      }
      case spv::OpExecutionMode:
      case spv::OpExecutionModeId: {
        if (!need(3)) break;
        for (EntryPoint& ep : entryPoints) {
          if (ep.function != in.word(1)) continue;
          ep.modes.push_back(in.word(2));
          if (in.word(2) == spv::ExecutionModeLocalSize && need(6)) {
            for (int i = 0; i < 3; ++i) ep.localSize[i] = in.word(3 + i);
          } else if (in.word(2) == spv::ExecutionModeLocalSizeId && need(6)) {
            for (int i = 0; i < 3; ++i) ep.localSizeId[i] = in.word(3 + i);
          }
        }
        break;
      }
      case spv::OpDecorate:
      case spv::OpDecorateId:
        if (need(3)) setDecoration(decorations[in.word(1)], in, 2);
        break;
      case spv::OpMemberDecorate: {
        if (!need(4)) break;
        auto& v = memberDecorations[in.word(1)];
        uint32_t m = in.word(2);
        if (m > 65535) return fail(in.offset, "member index out of range");
        if (v.size() <= m) v.resize(m + 1);
        setDecoration(v[m], in, 3);
        break;
      }
      case spv::OpTypeVoid: types[in.word(1)].kind = Type::Void; break;
      case spv::OpTypeBool: types[in.word(1)].kind = Type::Bool; break;
      case spv::OpTypeInt: {
        Type& t = types[in.word(1)];
        t.kind = Type::Int;
        t.width = in.word(2);
        t.isSigned = in.word(3) != 0;
        break;
      }
      case spv::OpTypeFloat: {
        Type& t = types[in.word(1)];
        t.kind = Type::Float;
        t.width = in.word(2);
        break;
      }
      case spv::OpTypeVector:
      case spv::OpTypeMatrix: {
        Type& t = types[in.word(1)];
        t.kind = in.op == spv::OpTypeVector ? Type::Vector : Type::Matrix;
        t.element = in.word(2);
        t.count = in.word(3);
        break;
      }
      case spv::OpTypeArray: {
        Type& t = types[in.word(1)];
        t.kind = Type::Array;
        t.element = in.word(2);
        uint64_t n = 0;
        // A length computed by OpSpecConstantOp is known once specialization constants are folded (the compiler
        // parses the folded module again); until then the array's length reads as 0.
        if (specConstantOp(in.word(3))) break;
        if (!constantU64(in.word(3), &n) || n == 0 || n > (1u << 28))
          return fail(in.offset, "array length is not a usable constant");
        t.count = uint32_t(n);
        break;
      }
      case spv::OpTypeRuntimeArray: {
        Type& t = types[in.word(1)];
        t.kind = Type::RuntimeArray;
        t.element = in.word(2);
        break;
      }
      case spv::OpTypeStruct: {
        Type& t = types[in.word(1)];
        t.kind = Type::Struct;
        for (uint32_t i = 2; i < in.count; ++i) t.members.push_back(in.word(i));
        break;
      }
      case spv::OpTypePointer: {
        if (!enumerant(2)) return fail(in.offset, "OpTypePointer storage class out of range");
        Type& t = types[in.word(1)];
        t.kind = Type::Pointer;
        t.storage = spv::StorageClass(in.word(2));
        t.element = in.word(3);
        break;
      }
      case spv::OpTypeFunction: {
        Type& t = types[in.word(1)];
        t.kind = Type::Function;
        t.element = in.word(2);
        for (uint32_t i = 3; i < in.count; ++i) t.members.push_back(in.word(i));
        break;
      }
      case spv::OpTypeImage:
      case spv::OpTypeSampler:
      case spv::OpTypeSampledImage:
      case spv::OpTypeOpaque:
      case spv::OpTypeAccelerationStructureKHR:
      case spv::OpTypeRayQueryKHR: types[in.word(1)].kind = Type::Opaque; break;
      case spv::OpConstantTrue:
      case spv::OpConstantFalse:
      case spv::OpSpecConstantTrue:
      case spv::OpSpecConstantFalse: {
        Constant& c = constants[in.word(2)];
        c.type = in.word(1);
        c.spec = in.op == spv::OpSpecConstantTrue || in.op == spv::OpSpecConstantFalse;
        c.words = {in.op == spv::OpConstantTrue || in.op == spv::OpSpecConstantTrue ? 1u : 0u};
        break;
      }
      case spv::OpConstant:
      case spv::OpSpecConstant: {
        if (!need(4)) return fail(in.offset, "short OpConstant");
        Constant& c = constants[in.word(2)];
        c.type = in.word(1);
        c.spec = in.op == spv::OpSpecConstant;
        c.words.assign(in.words + 3, in.words + in.count);
        break;
      }
      case spv::OpConstantComposite:
      case spv::OpSpecConstantComposite: {
        Constant& c = constants[in.word(2)];
        c.type = in.word(1);
        c.composite = true;
        c.spec = in.op == spv::OpSpecConstantComposite;
        c.elements.assign(in.words + 3, in.words + in.count);
        break;
      }
      case spv::OpConstantNull: {
        Constant& c = constants[in.word(2)];
        c.type = in.word(1);
        c.null = true;
        break;
      }
      default: break;
    }
  }
  // LocalSizeId and WorkgroupSize constants resolve once all constants are known.
  for (EntryPoint& ep : entryPoints) {
    for (int i = 0; i < 3; ++i) {
      if (!ep.localSizeId[i]) continue;
      uint64_t v = 0;
      if (specConstantOp(ep.localSizeId[i])) continue;  // known after folding, as array lengths above
      if (!constantU64(ep.localSizeId[i], &v)) return fail(0, "LocalSizeId operand is not a constant");
      ep.localSize[i] = uint32_t(v);
    }
  }
  for (auto& [id, d] : decorations) {
    if (d.builtIn != spv::BuiltInWorkgroupSize) continue;
    const Constant* c = constant(id);
    if (!c || !c->composite || c->elements.size() != 3) continue;
    for (EntryPoint& ep : entryPoints) {
      if (ep.model != spv::ExecutionModelGLCompute) continue;
      for (int i = 0; i < 3; ++i) {
        uint64_t v = 0;
        if (constantU64(c->elements[i], &v)) ep.localSize[i] = uint32_t(v);
      }
    }
  }
  return true;
}

bool Module::specConstantOp(uint32_t id) const {
  const Instruction* in = def(id);
  return in && in->op == spv::OpSpecConstantOp;
}

const Instruction* Module::def(uint32_t id) const {
  auto it = defs.find(id);
  return it == defs.end() ? nullptr : &instructions[it->second];
}

const Type* Module::type(uint32_t id) const {
  auto it = types.find(id);
  return it == types.end() ? nullptr : &it->second;
}

const Constant* Module::constant(uint32_t id) const {
  auto it = constants.find(id);
  return it == constants.end() ? nullptr : &it->second;
}

const Decorations& Module::decor(uint32_t id) const {
  static const Decorations none;
  auto it = decorations.find(id);
  return it == decorations.end() ? none : it->second;
}

const Decorations& Module::memberDecor(uint32_t structId, uint32_t member) const {
  static const Decorations none;
  auto it = memberDecorations.find(structId);
  if (it == memberDecorations.end() || member >= it->second.size()) return none;
  return it->second[member];
}

const EntryPoint* Module::findEntryPoint(const char* name, spv::ExecutionModel model) const {
  for (const EntryPoint& ep : entryPoints) {
    if (ep.model == model && ep.name == name) return &ep;
  }
  return nullptr;
}

bool Module::constantU64(uint32_t id, uint64_t* value) const {
  const Constant* c = constant(id);
  if (!c) return false;
  const Type* t = type(c->type);
  if (!t || t->kind != Type::Int) return false;
  if (c->null) {
    *value = 0;
    return true;
  }
  if (c->composite || c->words.empty()) return false;
  uint64_t v = c->words[0];
  if (t->width == 64 && c->words.size() > 1) v |= uint64_t(c->words[1]) << 32;
  if (t->width < 32) v &= (1ull << t->width) - 1;
  *value = v;
  return true;
}

uint32_t Module::typeOf(uint32_t id) const {
  const Instruction* in = def(id);
  if (!in) return 0;
  bool hasType = false;
  if (!hasResult(in->op, &hasType) || !hasType) return 0;
  return in->word(1);
}

bool applySpecialization(std::vector<uint32_t>& words, const std::vector<SpecValue>& values, std::string* error) {
  if (values.empty()) return true;
  Module m;
  if (!m.parse(words.data(), words.size(), error)) return false;
  std::map<uint32_t, const SpecValue*> byId;
  for (const SpecValue& v : values) byId[v.specId] = &v;
  std::vector<std::pair<uint32_t, uint32_t>> edits;  // word offset, new word
  for (const auto& [id, d] : m.decorations) {
    if (d.specId < 0) continue;
    auto it = byId.find(uint32_t(d.specId));
    if (it == byId.end()) continue;
    const Instruction* in = m.def(id);
    const Constant* c = m.constant(id);
    if (!in || !c || !c->spec) continue;
    const Type* t = m.type(c->type);
    const std::vector<uint8_t>& bytes = it->second->bytes;
    char buf[200];
    if (t && t->kind == Type::Bool) {
      // VkBool32.
      if (bytes.size() != 4) {
        std::snprintf(buf, sizeof buf,
                      "specialization constant %d is a bool but its map entry has size %zu (must be 4)", d.specId,
                      bytes.size());
        *error = buf;
        return false;
      }
      uint32_t v;
      std::memcpy(&v, bytes.data(), 4);
      uint32_t op = v ? spv::OpSpecConstantTrue : spv::OpSpecConstantFalse;
      edits.push_back({in->offset, (in->count << 16) | op});
      continue;
    }
    size_t size = t ? t->width / 8 : 0;
    if (bytes.size() != size) {
      std::snprintf(buf, sizeof buf, "specialization constant %d has %zu bytes but its map entry has size %zu",
                    d.specId, size, bytes.size());
      *error = buf;
      return false;
    }
    uint32_t lit[2] = {0, 0};
    std::memcpy(lit, bytes.data(), size);
    // Narrow integers are sign- or zero-extended into their literal word as the spec requires.
    if (t->kind == Type::Int && size < 4) {
      uint32_t bits = uint32_t(size * 8);
      uint32_t v = lit[0] & ((1u << bits) - 1);
      if (t->isSigned && (v >> (bits - 1))) v |= ~((1u << bits) - 1);
      lit[0] = v;
    } else if (t->kind == Type::Float && size == 2) {
      lit[0] &= 0xffff;
    }
    for (uint32_t i = 0; i + 3 < in->count && i < 2; ++i) edits.push_back({in->offset + 3 + i, lit[i]});
  }
  for (auto [at, w] : edits) words[at] = w;
  return true;
}

bool combinableAddOp(spv::Op op) {
  return op == spv::OpAtomicIAdd || op == spv::OpAtomicISub || op == spv::OpAtomicIIncrement ||
         op == spv::OpAtomicIDecrement;
}

bool relaxedSemantics(uint64_t semantics) {
  const uint64_t ordered = uint64_t(spv::MemorySemanticsAcquireMask) | spv::MemorySemanticsReleaseMask |
                           spv::MemorySemanticsAcquireReleaseMask | spv::MemorySemanticsSequentiallyConsistentMask |
                           spv::MemorySemanticsMakeAvailableMask | spv::MemorySemanticsMakeVisibleMask |
                           spv::MemorySemanticsVolatileMask;
  return (semantics & ordered) == 0;
}

void countBodyWords(const Module& m, std::unordered_map<uint32_t, uint32_t>& counts) {
  bool inBody = false;
  for (const Instruction& in : m.instructions) {
    if (in.op == spv::OpFunction) inBody = true;
    if (!inBody) continue;
    for (uint32_t w = 1; w < in.count; ++w) ++counts[in.words[w]];
  }
}

bool hasCombinableAdds(const uint32_t* words, size_t wordCount) {
  Module m;
  std::string error;
  if (!m.parse(words, wordCount, &error)) return false;
  std::unordered_map<uint32_t, uint32_t> counts;
  for (const Instruction& in : m.instructions) {
    uint64_t semantics = 0;
    if (!combinableAddOp(spv::Op(in.op)) || !m.constantU64(in.word(5), &semantics) || !relaxedSemantics(semantics))
      continue;
    if (counts.empty()) countBodyWords(m, counts);
    if (counts[in.word(2)] == 1) return true;
  }
  return false;
}

}  // namespace vkrt::spirv
