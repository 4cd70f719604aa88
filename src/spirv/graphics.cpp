// SPIR-V -> LLVM IR for vertex and fragment shaders: the Input/Output interface by Location and the built-ins
// (abi::GraphicsInvocation), fragment termination (OpKill, OpTerminateInvocation, demotion to a helper), helper lanes'
// writes, and the quad exchange behind derivatives and quad operations (abi.hpp's graphics section).
#include <algorithm>
#include <map>

#include <llvm/IR/Constants.h>
#include <spirv/unified1/GLSL.std.450.h>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

using abi::kFragmentDemoted;
using abi::kFragmentKilled;
using abi::kGraphicsLocations;

bool graphicsCapability(uint32_t cap) {
  switch (cap) {
    case spv::CapabilitySampleRateShading:
    case spv::CapabilityInterpolationFunction:  // InterpolateAt* (interpolateAt below)
    case spv::CapabilityClipDistance:
    case spv::CapabilityCullDistance:
    case spv::CapabilityDerivativeControl:
    case spv::CapabilityDemoteToHelperInvocation:
    case spv::CapabilityMultiView:
    case spv::CapabilityDrawParameters:
    case spv::CapabilityGroupNonUniformQuad:
    // What reading PrimitiveId and Layer in a fragment shader declares (the geometry stage itself is never compiled:
    // no CompileRequest names it; whether a device may use the capability is the runtime's geometryShader feature).
    case spv::CapabilityGeometry: return true;
    default: return false;
  }
}

namespace {

// The GraphicsInvocation field of a built-in in this stage and direction, and its bytes; -1 when there is none.
int builtInField(spv::ExecutionModel model, int builtIn, bool input, uint32_t* size) {
  *size = 4;
  if (model == spv::ExecutionModelVertex) {
    if (input) {
      switch (builtIn) {
        case spv::BuiltInVertexIndex: return offsetof(GraphicsInvocation, vertexIndex);
        case spv::BuiltInInstanceIndex: return offsetof(GraphicsInvocation, instanceIndex);
        case spv::BuiltInBaseVertex: return offsetof(GraphicsInvocation, baseVertex);
        case spv::BuiltInBaseInstance: return offsetof(GraphicsInvocation, baseInstance);
        case spv::BuiltInDrawIndex: return offsetof(GraphicsInvocation, drawIndex);
        case spv::BuiltInViewIndex: return offsetof(GraphicsInvocation, viewIndex);
        default: return -1;
      }
    }
    switch (builtIn) {
      case spv::BuiltInPosition: *size = 16; return offsetof(GraphicsInvocation, position);
      case spv::BuiltInPointSize: return offsetof(GraphicsInvocation, pointSize);
      case spv::BuiltInClipDistance: *size = 32; return offsetof(GraphicsInvocation, clipDistance);
      case spv::BuiltInCullDistance: *size = 32; return offsetof(GraphicsInvocation, cullDistance);
      default: return -1;
    }
  }
  if (input) {
    switch (builtIn) {
      case spv::BuiltInFragCoord: *size = 16; return offsetof(GraphicsInvocation, fragCoord);
      case spv::BuiltInPointCoord: *size = 8; return offsetof(GraphicsInvocation, pointCoord);
      case spv::BuiltInFrontFacing: return offsetof(GraphicsInvocation, frontFacing);
      case spv::BuiltInPrimitiveId: return offsetof(GraphicsInvocation, primitiveId);
      case spv::BuiltInSampleId: return offsetof(GraphicsInvocation, sampleId);
      case spv::BuiltInSamplePosition: *size = 8; return offsetof(GraphicsInvocation, samplePosition);
      case spv::BuiltInSampleMask: return offsetof(GraphicsInvocation, sampleMaskIn);
      case spv::BuiltInHelperInvocation: return offsetof(GraphicsInvocation, helper);
      case spv::BuiltInLayer: return offsetof(GraphicsInvocation, layer);
      case spv::BuiltInViewIndex: return offsetof(GraphicsInvocation, viewIndex);
      default: return -1;
    }
  }
  switch (builtIn) {
    case spv::BuiltInFragDepth: return offsetof(GraphicsInvocation, fragDepth);
    case spv::BuiltInSampleMask: return offsetof(GraphicsInvocation, sampleMaskOut);
    default: return -1;
  }
}

// Which members of struct variable `var` the code reaches: access chains with a constant first index name one; a
// load, store or copy of the whole variable, a chain with a computed first index, or passing it to a function count
// for all.
std::vector<bool> membersUsed(const Module& m, uint32_t var, size_t members) {
  std::vector<bool> used(members, false);
  for (const Instruction& in : m.instructions) {
    bool whole = false;
    switch (in.op) {
      case spv::OpAccessChain:
      case spv::OpInBoundsAccessChain: {
        if (in.word(3) != var) break;
        uint64_t k = 0;
        if (in.count > 4 && m.constantU64(in.word(4), &k) && k < members)
          used[k] = true;
        else
          whole = true;
        break;
      }
      case spv::OpLoad: whole = in.word(3) == var; break;
      case spv::OpStore: whole = in.word(1) == var; break;
      case spv::OpCopyMemory: whole = in.word(1) == var || in.word(2) == var; break;
      case spv::OpFunctionCall:
        for (uint32_t i = 4; i < in.count; ++i) whole |= in.word(i) == var;
        break;
      default: break;
    }
    if (whole) used.assign(members, true);
  }
  return used;
}

// Adds what one component at `location` tells to the per-location facts.
void noteLocation(std::map<uint32_t, GraphicsStageInfo::Location>& table, uint32_t location, uint32_t mask,
                  const Decorations& a, const Decorations& b, bool integer, bool wide) {
  {
    GraphicsStageInfo::Location& l = table[location];
    l.location = uint8_t(location);
    l.componentMask |= uint8_t(mask);
    if (a.flat || b.flat) l.interpolation = GraphicsStageInfo::Location::Flat;
    if (a.noPerspective || b.noPerspective) l.interpolation = GraphicsStageInfo::Location::NoPerspective;
    l.centroid |= a.centroid || b.centroid;
    l.sample |= a.sample || b.sample;
    l.integer |= integer;
    l.wide |= wide;
  }
}

// The location walk of "Location Assignment": a scalar or vector takes one location (a 64-bit vector of three or
// four components two), starting at component `component`; a matrix one per column; an array one run per element;
// a struct its members in order, a member's own Location restarting the count.
class InterfaceWalk {
 public:
  InterfaceWalk(Codegen& g, const Instruction& var, bool input, int slotsField,
                std::map<uint32_t, GraphicsStageInfo::Location>& table)
      : g_(g), var_(var), input_(input), slotsField_(slotsField), table_(table) {}

  bool walk(uint32_t typeId, uint64_t priv, uint32_t& location, uint32_t component, const Decorations& outer,
            const Decorations& member) {
    const Type& t = g_.spvType(typeId);
    switch (t.kind) {
      case Type::Int:
      case Type::Float:
      case Type::Vector: return leaf(typeId, priv, location, component, outer, member);
      case Type::Matrix:
        for (uint32_t i = 0; i < t.count; ++i)
          if (!leaf(t.element, priv + uint64_t(i) * g_.naturalMatrixStride(typeId), location, component, outer, member))
            return false;
        return true;
      case Type::Array: {
        uint64_t stride = g_.arrayStride(typeId, 0, false);
        for (uint32_t i = 0; i < t.count; ++i)
          if (!walk(t.element, priv + i * stride, location, component, outer, member)) return false;
        return true;
      }
      case Type::Struct:
        for (uint32_t i = 0; i < t.members.size(); ++i) {
          const Decorations& md = g_.m.memberDecor(typeId, i);
          if (md.location >= 0) location = uint32_t(md.location);
          uint32_t c = md.component >= 0 ? uint32_t(md.component) : 0;
          if (!walk(t.members[i], priv + g_.memberOffset(typeId, i), location, c, outer, md)) return false;
        }
        return true;
      default: return g_.unsupported(var_, "interface variable type (booleans, pointers or runtime arrays)");
    }
  }

 private:
  bool leaf(uint32_t typeId, uint64_t priv, uint32_t& location, uint32_t component, const Decorations& outer,
            const Decorations& member) {
    const Type& st = g_.spvType(g_.scalarType(typeId));
    uint32_t n = g_.componentCount(typeId);
    uint32_t width = st.width;
    uint32_t step = width == 64 ? 2 : 1;  // components a scalar takes
    for (uint32_t k = 0; k < n; ++k) {
      uint32_t pos = component + k * step;
      uint32_t loc = location + pos / 4, c = pos % 4;
      if (loc >= kGraphicsLocations) return g_.fail(var_, "interface variable beyond the last location");
      g_.ioCopies.push_back({input_, priv + uint64_t(k) * (width / 8), slotsField_, 16 * loc + 4 * c, width / 8});
      noteLocation(table_, loc, (width == 64 ? 3u : 1u) << c, outer, member, st.kind == Type::Int, width == 64);
    }
    location += (width == 64 && n > 2) ? 2 : 1;
    return true;
  }

  Codegen& g_;
  const Instruction& var_;
  bool input_;
  int slotsField_;
  std::map<uint32_t, GraphicsStageInfo::Location>& table_;
};

}  // namespace

bool Codegen::declareInterface(const Instruction& var, Global& g) {
  uint32_t id = var.word(2);
  uint32_t typeId = spvType(var.word(1)).element;
  const Decorations& d = m.decor(id);
  bool input = g.storage == spv::StorageClassInput;
  GraphicsStageInfo& gi = info.graphics;
  // Notes what a built-in tells the pipeline (`count`: elements of an array built-in).
  auto noteBuiltIn = [&](int builtIn, uint32_t count) {
    switch (builtIn) {
      case spv::BuiltInClipDistance: gi.clipDistances = count; break;
      case spv::BuiltInCullDistance: gi.cullDistances = count; break;
      case spv::BuiltInPointSize: gi.writesPointSize = true; break;
      case spv::BuiltInFragDepth: gi.writesDepth = true; break;
      case spv::BuiltInSampleMask: (input ? gi.readsSampleMask : gi.writesSampleMask) = true; break;
      case spv::BuiltInPointCoord:
        if (input) gi.readsPointCoord = true;
        break;
      case spv::BuiltInSampleId:
      case spv::BuiltInSamplePosition: gi.readsSampleId = true; break;
      case spv::BuiltInFragCoord:
        if (input) gi.readsFragCoord = true;
        break;
      default: break;
    }
  };
  auto elements = [&](uint32_t t) { return spvType(t).kind == Type::Array ? spvType(t).count : 1u; };
  if (input && (d.builtIn == spv::BuiltInDeviceIndex || d.builtIn == spv::BuiltInSubgroupSize ||
                d.builtIn == spv::BuiltInSubgroupLocalInvocationId)) {
    // As in compute shaders (variablePtr): one physical device, subgroups of one invocation.
    g.builtIn = d.builtIn;
    return true;
  }
  if (d.builtIn >= 0) {
    // A built-in variable: read or written in place.
    uint32_t size = 0;
    int field = builtInField(model, d.builtIn, input, &size);
    if (field < 0) return unsupported(var, "built-in variable not supported in this stage");
    uint64_t bytes = layoutSize(typeId, 0, false);
    if (bytes > size) return fail(var, "built-in variable larger than the stage supports (8 clip or cull distances)");
    g.graphicsField = field;
    g.size = bytes;
    noteBuiltIn(d.builtIn, elements(typeId));
    // An output built-in's initializer is its value until the shader stores one (OpVariable "Initializer"): a
    // FragDepth initialized and never stored writes that depth (CTS renderpass.depth_stencil_write_conditions.*).
    if (!input && var.count > 4) privateInits.push_back({id, var.word(4)});
    return true;
  }
  // Storage in the private block, copied from or to the invocation.
  g.size = layoutSize(typeId, 0, false);
  g.offset = (privateSize + 15) / 16 * 16;
  privateSize = g.offset + g.size;
  g.inPrivate = true;
  if (var.count > 4) privateInits.push_back({id, var.word(4)});
  const Type& t = spvType(typeId);
  if (t.kind == Type::Struct && !t.members.empty() && m.memberDecor(typeId, 0).builtIn >= 0) {
    // A block of built-ins (gl_PerVertex): each member the code uses goes to its field.
    std::vector<bool> used = membersUsed(m, id, t.members.size());
    for (uint32_t i = 0; i < t.members.size(); ++i) {
      int builtIn = m.memberDecor(typeId, i).builtIn;
      if (builtIn < 0) return fail(var, "a block mixes built-in and user members");
      if (!used[i]) continue;
      uint32_t size = 0;
      int field = builtInField(model, builtIn, input, &size);
      if (field < 0) return unsupported(var, "built-in block member not supported in this stage");
      uint64_t bytes = layoutSize(t.members[i], 0, false);
      if (bytes > size) return fail(var, "built-in member larger than the stage supports (8 clip or cull distances)");
      ioCopies.push_back({input, g.offset + memberOffset(typeId, i), -1, uint32_t(field), uint32_t(bytes)});
      noteBuiltIn(builtIn, elements(t.members[i]));
    }
    return true;
  }
  // User locations.
  int slotsField = input ? int(offsetof(GraphicsInvocation, inputs)) : int(offsetof(GraphicsInvocation, outputs));
  bool second = !input && isFragment() && d.index == 1;
  if (second) {
    slotsField = int(offsetof(GraphicsInvocation, outputs1));
    if (d.location != 0) return fail(var, "an Index 1 output at a location other than 0");
    gi.dualSource = true;
  }
  if (d.location < 0 && t.kind != Type::Struct) return fail(var, "interface variable without a Location");
  if (d.sample && input) gi.readsSampleId = true;
  std::map<uint32_t, GraphicsStageInfo::Location> secondSource;  // not a color attachment: not listed
  auto& table = second ? secondSource : input ? inputLocations : outputLocations;
  uint32_t location = d.location >= 0 ? uint32_t(d.location) : 0;
  InterfaceWalk w(*this, var, input, slotsField, table);
  static const Decorations none;
  if (!w.walk(typeId, g.offset, location, d.component >= 0 ? uint32_t(d.component) : 0, d, none)) return false;
  gi.inputs.clear();
  for (auto& [loc, l] : inputLocations) gi.inputs.push_back(l);
  gi.outputs.clear();
  for (auto& [loc, l] : outputLocations) gi.outputs.push_back(l);
  return true;
}

void Codegen::copyInterface(bool inputs) {
  for (const IoCopy& c : ioCopies) {
    if (c.input != inputs) continue;
    llvm::Value* base = ctxArg;
    if (c.slotsField >= 0)
      base = b.CreateAlignedLoad(b.getPtrTy(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, unsigned(c.slotsField)),
                                 llvm::Align(8));
    llvm::Value* there = b.CreateConstGEP1_64(b.getInt8Ty(), base, c.at);
    llvm::Value* here = b.CreateConstGEP1_64(b.getInt8Ty(), privArg, c.privOffset);
    llvm::Type* ty = b.getIntNTy(c.bytes * 8);
    if (c.bytes > 8) ty = llvm::ArrayType::get(b.getInt32Ty(), c.bytes / 4);
    llvm::Align align(std::min<uint32_t>(c.bytes, 4));
    if (inputs)
      b.CreateAlignedStore(b.CreateAlignedLoad(ty, there, align), here, align);
    else
      b.CreateAlignedStore(b.CreateAlignedLoad(ty, here, align), there, align);
  }
}

bool Codegen::graphicsModes(const EntryPoint& ep) {
  if (!isFragment()) return true;
  for (uint32_t mode : ep.modes) {
    switch (mode) {
      case spv::ExecutionModePixelCenterInteger:
        error = "execution mode PixelCenterInteger is not allowed in Vulkan (fragment centers are at half integers)";
        return false;
      case spv::ExecutionModeOriginLowerLeft:
        error = "execution mode OriginLowerLeft is not allowed in Vulkan (OriginUpperLeft is required)";
        return false;
      case spv::ExecutionModeEarlyFragmentTests: info.graphics.earlyFragmentTests = true; break;
      case spv::ExecutionModePixelInterlockOrderedEXT:
      case spv::ExecutionModePixelInterlockUnorderedEXT:
      case spv::ExecutionModeSampleInterlockOrderedEXT:
      case spv::ExecutionModeSampleInterlockUnorderedEXT:
      case spv::ExecutionModeShadingRateInterlockOrderedEXT:
      case spv::ExecutionModeShadingRateInterlockUnorderedEXT:
      case spv::ExecutionModePostDepthCoverage:
      case spv::ExecutionModeStencilRefReplacingEXT: {
        char buf[96];
        std::snprintf(buf, sizeof buf, "unsupported fragment execution mode %u", mode);
        error = buf;
        return false;
      }
      default: break;  // OriginUpperLeft, Depth*: nothing to do
    }
  }
  return true;
}

namespace {
llvm::Value* field(Codegen& g, size_t offset) { return g.b.CreateConstGEP1_64(g.b.getInt8Ty(), g.ctxArg, offset); }
}  // namespace

llvm::Value* Codegen::helperLane() {
  if (!isFragment()) return b.getFalse();
  llvm::Value* h =
      b.CreateAlignedLoad(b.getInt32Ty(), field(*this, offsetof(GraphicsInvocation, helper)), llvm::Align(4));
  return b.CreateICmpNE(h, i32(0));
}

Ptr Codegen::forWrite(const Ptr& p) {
  bool buffer = p.storage == spv::StorageClassStorageBuffer || p.storage == spv::StorageClassUniform ||
                p.storage == spv::StorageClassPhysicalStorageBuffer;
  if (!buffer) return p;
  info.graphics.sideEffects = true;
  if (!isFragment() || p.slot >= 0) return p;
  Ptr q = p;
  q.helper = helperLane();
  q.unmaskedLimit = p.limit;
  q.limit = b.CreateSelect(q.helper, i64(0), p.limit);
  return q;
}

llvm::Value* Codegen::writableRecord(llvm::Value* record) {
  info.graphics.sideEffects = true;
  if (!isFragment()) return record;
  return b.CreateSelect(helperLane(), zeros, record);
}

void Codegen::quadExchange(llvm::Value* v, llvm::Value* out[4]) {
  info.graphics.needsQuad = true;
  llvm::Value* parityAt = field(*this, offsetof(GraphicsInvocation, quadParity));
  llvm::Value* parity = b.CreateAlignedLoad(b.getInt32Ty(), parityAt, llvm::Align(4));
  llvm::Value* lane =
      b.CreateAlignedLoad(b.getInt32Ty(), field(*this, offsetof(InvocationContext, localIndex)), llvm::Align(4));
  auto area = [&] {
    llvm::Value* exchange =
        b.CreateAlignedLoad(b.getPtrTy(), field(*this, offsetof(InvocationContext, workgroupMemory)), llvm::Align(8));
    return b.CreateGEP(b.getInt8Ty(), exchange, b.CreateMul(b.CreateZExt(parity, b.getInt64Ty()), i64(64)));
  };
  llvm::Value* half = area();
  b.CreateAlignedStore(v, b.CreateGEP(b.getInt8Ty(), half, b.CreateMul(b.CreateZExt(lane, b.getInt64Ty()), i64(16))),
                       llvm::Align(4));
  llvm::Value* barrier =
      b.CreateAlignedLoad(b.getPtrTy(), field(*this, offsetof(InvocationContext, barrier)), llvm::Align(8));
  b.CreateCall(llvm::FunctionType::get(b.getVoidTy(), {b.getPtrTy()}, false), barrier, {ctxArg});
  half = area();  // the barrier may have moved nothing, but the loads must follow it
  for (int k = 0; k < 4; ++k)
    out[k] = b.CreateAlignedLoad(v->getType(), b.CreateConstGEP1_64(b.getInt8Ty(), half, 16 * k), llvm::Align(4));
  b.CreateAlignedStore(b.CreateXor(parity, i32(1)), parityAt, llvm::Align(4));
}

void Codegen::derivatives(llvm::Value* v, bool coarse, llvm::Value** dx, llvm::Value** dy) {
  if (!isFragment()) {
    *dx = *dy = llvm::Constant::getNullValue(v->getType());
    return;
  }
  if (spmdDerivatives) {
    *dx = spmdDx ? spmdDx : llvm::Constant::getNullValue(v->getType());
    *dy = spmdDy ? spmdDy : llvm::Constant::getNullValue(v->getType());
    return;
  }
  llvm::Value* q[4];
  quadExchange(v, q);
  if (coarse) {
    *dx = b.CreateFSub(q[1], q[0]);
    *dy = b.CreateFSub(q[2], q[0]);
    return;
  }
  llvm::Value* lane =
      b.CreateAlignedLoad(b.getInt32Ty(), field(*this, offsetof(InvocationContext, localIndex)), llvm::Align(4));
  llvm::Value* odd = b.CreateICmpNE(b.CreateAnd(lane, i32(2)), i32(0));    // the bottom row
  llvm::Value* right = b.CreateICmpNE(b.CreateAnd(lane, i32(1)), i32(0));  // the right column
  *dx = b.CreateSelect(odd, b.CreateFSub(q[3], q[2]), b.CreateFSub(q[1], q[0]));
  *dy = b.CreateSelect(right, b.CreateFSub(q[3], q[1]), b.CreateFSub(q[2], q[0]));
}

bool Codegen::interpolateAt(const Instruction& in, uint32_t inst, bool& ok) {
  // GLSL.std.450 InterpolateAtCentroid / Sample / Offset: `interpolant` points into an Input variable (or a part of
  // one). The runtime interpolates every input location at the position; the variable's copies from the location
  // slots (declareInterface) then fill a scratch copy of the variable, read at the interpolant's offset.
  if (!isFragment()) return (ok = fail(in, "InterpolateAt* outside a fragment shader")), true;
  uint32_t root = in.count > 5 ? in.word(5) : 0;
  for (const Instruction* d = m.def(root);
       d && (d->op == spv::OpAccessChain || d->op == spv::OpInBoundsAccessChain || d->op == spv::OpCopyObject);
       d = m.def(root))
    root = d->word(3);
  auto git = globals.find(root);
  if (git == globals.end() || git->second.storage != spv::StorageClassInput || !git->second.inPrivate ||
      (!hasPtr(in.word(5)) && !globals.count(in.word(5))))
    return (ok = fail(in, "interpolant is not a user Input variable or a part of one")), true;
  const Global& g = git->second;
  Ptr p = ptr(in.word(5));
  if (!p.base || !isFloat(p.type)) return (ok = fail(in, "interpolant is not a float scalar or vector")), true;
  // The rasterizer interpolates 32-bit floats (the slots' words).
  if (spvType(scalarType(p.type)).width != 32)
    return (ok = unsupported(in, "InterpolateAt* of a float that is not 32 bits")), true;
  llvm::Value* sampleV = i32(0);
  llvm::Value* dx = llvm::ConstantFP::get(b.getFloatTy(), 0);
  llvm::Value* dy = dx;
  uint32_t where = abi::kInterpolateAtCentroid;
  if (inst == GLSLstd450InterpolateAtSample) {
    where = abi::kInterpolateAtSample;
    llvm::Value* v = in.count > 6 ? value(in.word(6)) : nullptr;
    if (!v || !v->getType()->isIntegerTy()) return (ok = fail(in, "sample is not an integer")), true;
    sampleV = b.CreateSExtOrTrunc(v, b.getInt32Ty());
  } else if (inst == GLSLstd450InterpolateAtOffset) {
    where = abi::kInterpolateAtOffset;
    llvm::Value* v = in.count > 6 ? value(in.word(6)) : nullptr;
    auto* vt = v ? llvm::dyn_cast<llvm::FixedVectorType>(v->getType()) : nullptr;
    if (!vt || vt->getNumElements() != 2 || !vt->getElementType()->isFloatingPointTy())
      return (ok = fail(in, "offset is not a 2-component float vector")), true;
    dx = b.CreateFPCast(b.CreateExtractElement(v, uint64_t(0)), b.getFloatTy());
    dy = b.CreateFPCast(b.CreateExtractElement(v, uint64_t(1)), b.getFloatTy());
  }
  llvm::Type* slotsTy = llvm::ArrayType::get(b.getInt32Ty(), kGraphicsLocations * 4);
  llvm::Type* varTy = llvm::ArrayType::get(b.getInt8Ty(), std::max<uint64_t>(g.size, 1));
  llvm::AllocaInst *slots, *copy;
  {
    llvm::IRBuilderBase::InsertPointGuard guard(b);
    b.SetInsertPoint(allocaBlock, allocaBlock->begin());
    slots = b.CreateAlloca(slotsTy);
    slots->setAlignment(llvm::Align(16));
    copy = b.CreateAlloca(varTy);
    copy->setAlignment(llvm::Align(16));
  }
  llvm::Value* fnAt = field(*this, offsetof(GraphicsInvocation, interpolateAt));
  llvm::Value* fnPtr = b.CreateAlignedLoad(b.getPtrTy(), fnAt, llvm::Align(8));
  llvm::FunctionType* fty = llvm::FunctionType::get(
      b.getVoidTy(), {b.getPtrTy(), b.getInt32Ty(), b.getInt32Ty(), b.getFloatTy(), b.getFloatTy(), b.getPtrTy()},
      false);
  b.CreateCall(fty, fnPtr, {ctxArg, i32(where), sampleV, dx, dy, slots});
  // The variable's input copies, from the scratch slots to the scratch variable.
  for (const IoCopy& c : ioCopies) {
    if (!c.input || c.slotsField != int(offsetof(GraphicsInvocation, inputs)) || c.privOffset < g.offset ||
        c.privOffset + c.bytes > g.offset + g.size)
      continue;
    llvm::Type* ty = b.getIntNTy(c.bytes * 8);
    llvm::Align align(std::min<uint32_t>(c.bytes, 4));
    llvm::Value* v = b.CreateAlignedLoad(ty, b.CreateConstGEP1_64(b.getInt8Ty(), slots, c.at), align);
    b.CreateAlignedStore(v, b.CreateConstGEP1_64(b.getInt8Ty(), copy, c.privOffset - g.offset), align);
  }
  Ptr q = p;
  q.base = copy;
  q.limit = i64(g.size);
  q.storage = spv::StorageClassFunction;
  llvm::Value* r = load(q);
  if (!r) return (ok = fail(in, "interpolant could not be read")), true;
  set(in.word(2), r);
  return true;
}

llvm::Value* derivativeResult(llvm::IRBuilder<>& b, spv::Op op, llvm::Value* dx, llvm::Value* dy) {
  switch (op) {
    case spv::OpDPdx:
    case spv::OpDPdxFine:
    case spv::OpDPdxCoarse: return dx;
    case spv::OpDPdy:
    case spv::OpDPdyFine:
    case spv::OpDPdyCoarse: return dy;
    default:
      return b.CreateFAdd(b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, dx),
                          b.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, dy));
  }
}

bool Codegen::graphics(const Instruction& in, bool& ok) {
  switch (in.op) {
    case spv::OpKill:
    case spv::OpTerminateInvocation:
      if (!isFragment()) return (ok = unsupported(in, "outside a fragment shader")), true;
      info.graphics.canDiscard = true;
      b.CreateAlignedStore(i32(kFragmentKilled), field(*this, offsetof(GraphicsInvocation, status)), llvm::Align(4));
      returnFromFunction();
      return true;
    case spv::OpDemoteToHelperInvocation:
      if (!isFragment()) return (ok = unsupported(in, "outside a fragment shader")), true;
      info.graphics.canDiscard = true;
      b.CreateAlignedStore(i32(kFragmentDemoted), field(*this, offsetof(GraphicsInvocation, status)), llvm::Align(4));
      b.CreateAlignedStore(i32(1), field(*this, offsetof(GraphicsInvocation, helper)), llvm::Align(4));
      return true;
    case spv::OpIsHelperInvocationEXT: set(in.word(2), helperLane()); return true;
    case spv::OpDPdx:
    case spv::OpDPdy:
    case spv::OpFwidth:
    case spv::OpDPdxFine:
    case spv::OpDPdyFine:
    case spv::OpFwidthFine:
    case spv::OpDPdxCoarse:
    case spv::OpDPdyCoarse:
    case spv::OpFwidthCoarse: {
      llvm::Value* v = value(in.word(3));
      if (!v || !isFloat(m.typeOf(in.word(3))) || componentCount(m.typeOf(in.word(3))) > 4)
        return (ok = fail(in, "derivative of a value that is not a float scalar or vector")), true;
      // The exchange carries 32-bit floats.
      llvm::Type* ty = v->getType();
      llvm::Type* f32 = ty->isVectorTy()
                            ? llvm::FixedVectorType::get(b.getFloatTy(), componentCount(m.typeOf(in.word(3))))
                            : b.getFloatTy();
      llvm::Value* x = b.CreateFPCast(v, f32);
      bool coarse = in.op == spv::OpDPdxCoarse || in.op == spv::OpDPdyCoarse || in.op == spv::OpFwidthCoarse;
      llvm::Value *dx, *dy;
      derivatives(x, coarse, &dx, &dy);
      set(in.word(2), b.CreateFPCast(derivativeResult(b, in.op, dx, dy), ty));
      return true;
    }
    case spv::OpGroupNonUniformQuadBroadcast:
    case spv::OpGroupNonUniformQuadSwap: {
      if (!isFragment()) return (ok = unsupported(in, "quad operations outside fragment shaders")), true;
      uint64_t scope = 0;
      if (!m.constantU64(in.word(3), &scope) || scope != spv::ScopeSubgroup)
        return (ok = fail(in, "quad operation scope is not Subgroup")), true;
      llvm::Value* v = value(in.word(4));
      llvm::Value* sel = value(in.word(5));
      if (!v || !sel) return (ok = fail(in, "operand has no value")), true;
      llvm::Type* ty = v->getType();
      uint64_t bytes = layoutSize(m.typeOf(in.word(4)), 0, false);
      if (bytes > 16 || ty->isStructTy() || ty->isArrayTy())
        return (ok = unsupported(in, "quad operation on a value over 16 bytes")), true;
      bool isBool = ty->getScalarType()->isIntegerTy(1);
      llvm::Type* carried = ty;
      if (isBool) {
        carried = b.getInt32Ty();
        if (auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(ty))
          carried = llvm::FixedVectorType::get(b.getInt32Ty(), vt->getNumElements());
      }
      llvm::Value* q[4];
      quadExchange(isBool ? b.CreateZExt(v, carried) : v, q);
      llvm::Value* index;
      if (in.op == spv::OpGroupNonUniformQuadBroadcast) {
        index = b.CreateAnd(b.CreateZExtOrTrunc(sel, b.getInt32Ty()), i32(3));
      } else {
        // Direction 0: horizontal (lane ^ 1), 1: vertical (lane ^ 2), 2: diagonal (lane ^ 3).
        llvm::Value* lane =
            b.CreateAlignedLoad(b.getInt32Ty(), field(*this, offsetof(InvocationContext, localIndex)), llvm::Align(4));
        llvm::Value* d = b.CreateZExtOrTrunc(sel, b.getInt32Ty());
        index = b.CreateXor(lane, b.CreateAdd(d, i32(1)));
        index = b.CreateAnd(index, i32(3));
      }
      llvm::Value* r = b.CreateSelect(b.CreateICmpEQ(index, i32(0)), q[0],
                                      b.CreateSelect(b.CreateICmpEQ(index, i32(1)), q[1],
                                                     b.CreateSelect(b.CreateICmpEQ(index, i32(2)), q[2], q[3])));
      if (isBool) r = b.CreateICmpNE(r, llvm::Constant::getNullValue(carried));
      set(in.word(2), r);
      return true;
    }
    default: return false;
  }
}

}  // namespace vkrt::spirv
