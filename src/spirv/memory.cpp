// SPIR-V -> LLVM IR: variables, access chains, loads, stores, atomics, descriptors (see codegen.hpp's memory
// model).
#include <algorithm>
#include <unordered_set>

#include <llvm/IR/Constants.h>
#include <llvm/IR/MDBuilder.h>

#include "abi/shader_debug.hpp"
#include "spirv/codegen.hpp"
#include "spirv/newer_tokens.hpp"

namespace vkrt::spirv {

namespace {

// Offset of a built-in in the context (InvocationContext for compute, RayInvocation for the ray tracing
// stages), and its size; -1 when the stage has no such built-in.
int builtInOffset(int builtIn, bool rayTracing, uint32_t* size) {
  *size = 12;
  if (!rayTracing) {
    switch (builtIn) {
      case spv::BuiltInGlobalInvocationId: return offsetof(InvocationContext, globalId);
      case spv::BuiltInLocalInvocationId: return offsetof(InvocationContext, localId);
      case spv::BuiltInWorkgroupId: return offsetof(InvocationContext, workgroupId);
      case spv::BuiltInNumWorkgroups: return offsetof(InvocationContext, numWorkgroups);
      case spv::BuiltInWorkgroupSize: return offsetof(InvocationContext, workgroupSize);
      case spv::BuiltInLocalInvocationIndex:
      case spv::BuiltInSubgroupId:  // one invocation per subgroup
        *size = 4;
        return offsetof(InvocationContext, localIndex);
      default: return -1;
    }
  }
  switch (builtIn) {
    case spv::BuiltInLaunchIdKHR: return offsetof(RayInvocation, launchId);
    case spv::BuiltInLaunchSizeKHR: return offsetof(RayInvocation, launchSize);
    case spv::BuiltInWorldRayOriginKHR: return offsetof(RayInvocation, worldRayOrigin);
    case spv::BuiltInWorldRayDirectionKHR: return offsetof(RayInvocation, worldRayDirection);
    case spv::BuiltInObjectRayOriginKHR: return offsetof(RayInvocation, objectRayOrigin);
    case spv::BuiltInObjectRayDirectionKHR: return offsetof(RayInvocation, objectRayDirection);
    case spv::BuiltInObjectToWorldKHR: *size = 48; return offsetof(RayInvocation, objectToWorld);
    case spv::BuiltInWorldToObjectKHR: *size = 48; return offsetof(RayInvocation, worldToObject);
    case kBuiltInHitTriangleVertexPositionsKHR: *size = 36; return offsetof(RayInvocation, hitTriangleVertexPositions);
    default: break;
  }
  *size = 4;
  switch (builtIn) {
    case spv::BuiltInRayTminKHR: return offsetof(RayInvocation, rayTmin);
    case spv::BuiltInRayTmaxKHR:
    case spv::BuiltInHitTNV: return offsetof(RayInvocation, rayTmax);
    case spv::BuiltInIncomingRayFlagsKHR: return offsetof(RayInvocation, incomingRayFlags);
    case spv::BuiltInCullMaskKHR: return offsetof(RayInvocation, cullMask);
    case spv::BuiltInInstanceCustomIndexKHR: return offsetof(RayInvocation, instanceCustomIndex);
    case spv::BuiltInInstanceId: return offsetof(RayInvocation, instanceId);
    case spv::BuiltInPrimitiveId: return offsetof(RayInvocation, primitiveId);
    case spv::BuiltInRayGeometryIndexKHR: return offsetof(RayInvocation, geometryIndex);
    case spv::BuiltInHitKindKHR: return offsetof(RayInvocation, hitKind);
    default: return -1;
  }
}

}  // namespace

bool Codegen::declareGlobals() {
  uint64_t workgroupSize = 0;
  // The ids the functions' instructions name (the module holds only the entry point's call tree by now). A
  // descriptor variable none of them names is not statically used (SPIR-V 1.4 modules list every global in
  // OpEntryPoint's interface, used or not): it gets no resource slot, so the pipeline's use of descriptors (the
  // "-None-08114" rule, VUID-vkCmdDispatch-None-08114) leaves it out. Operand words that are literals may add ids
  // too; that only keeps a variable.
  std::unordered_set<uint32_t> named;
  bool inFunctions = false;
  for (const Instruction& in : m.instructions) {
    inFunctions = inFunctions || in.op == spv::OpFunction;
    if (inFunctions)
      for (uint32_t w = 1; w < in.count; ++w) named.insert(in.words[w]);
  }
  for (const Instruction& in : m.instructions) {
    if (in.op == spv::OpFunction) break;
    if (in.op != spv::OpVariable) continue;
    uint32_t id = in.word(2);
    const Type& pt = spvType(in.word(1));
    Global g;
    g.storage = spv::StorageClass(in.word(3));
    const Decorations& d = m.decor(id);
    switch (g.storage) {
      case spv::StorageClassPrivate:
        g.size = layoutSize(pt.element, 0, false);
        g.offset = (privateSize + 15) / 16 * 16;
        privateSize = g.offset + g.size;
        if (in.count > 4) privateInits.push_back({id, in.word(4)});
        break;
      case spv::StorageClassWorkgroup:
        // Workgroup memory is zeroed for every workgroup (exec/compute.cpp), which is what an initializer can ask
        // (VK_KHR_zero_initialize_workgroup_memory: OpConstantNull only).
        g.size = layoutSize(pt.element, 0, false);
        if (m.decor(pt.element).block) {
          // SPV_KHR_workgroup_memory_explicit_layout: Block-decorated Workgroup variables are laid out by their
          // Offset/ArrayStride decorations and all alias one another from the start of workgroup memory.
          g.offset = 0;
          workgroupSize = std::max(workgroupSize, g.size);
        } else {
          g.offset = (workgroupSize + 15) / 16 * 16;
          workgroupSize = g.offset + g.size;
        }
        break;
      case spv::StorageClassInput:
      case spv::StorageClassOutput:
        if (isGraphics()) {
          if (!declareInterface(in, g)) return false;
        } else if (g.storage == spv::StorageClassInput) {
          g.builtIn = d.builtIn;
        }
        break;
      // Ray tracing storage classes (abi.hpp says where each lives).
      case spv::StorageClassRayPayloadKHR:
      case spv::StorageClassCallableDataKHR:
      case spv::StorageClassHitAttributeKHR:
      case spv::StorageClassIncomingRayPayloadKHR:
      case spv::StorageClassIncomingCallableDataKHR: {
        g.size = layoutSize(pt.element, 0, false);
        uint32_t bytes = uint32_t(std::min<uint64_t>(g.size, UINT32_MAX));
        RayStageInfo& r = info.ray;
        if (g.storage == spv::StorageClassRayPayloadKHR || g.storage == spv::StorageClassIncomingRayPayloadKHR)
          r.payloadBytes = std::max(r.payloadBytes, bytes);
        else if (g.storage == spv::StorageClassHitAttributeKHR)
          r.hitAttributeBytes = std::max(r.hitAttributeBytes, bytes);
        else
          r.callableDataBytes = std::max(r.callableDataBytes, bytes);
        bool own = g.storage == spv::StorageClassRayPayloadKHR || g.storage == spv::StorageClassCallableDataKHR ||
                   (g.storage == spv::StorageClassHitAttributeKHR && model == spv::ExecutionModelIntersectionKHR);
        if (own) {
          // The invocation's own: in its private block.
          g.offset = (privateSize + 15) / 16 * 16;
          privateSize = g.offset + g.size;
          if (g.storage == spv::StorageClassHitAttributeKHR) hitAttributeVar = id;
        } else if (g.storage == spv::StorageClassHitAttributeKHR) {
          g.contextField = offsetof(RayInvocation, hitAttributes);
          r.readsHitAttributes = true;
        } else {
          g.contextField = offsetof(RayInvocation, incoming);
        }
        break;
      }
      case spv::StorageClassShaderRecordBufferKHR: g.contextField = offsetof(RayInvocation, shaderRecord); break;
      case spv::StorageClassUniform:
      case spv::StorageClassStorageBuffer: {
        if (!named.count(id)) break;
        const Type& inner = spvType(pt.element);
        ResourceBinding r;
        r.set = uint32_t(std::max(d.set, 0));
        r.binding = uint32_t(std::max(d.binding, 0));
        r.arraySize = inner.kind == Type::Array ? inner.count : inner.kind == Type::RuntimeArray ? 0 : 1;
        uint32_t block = inner.kind == Type::Array || inner.kind == Type::RuntimeArray ? inner.element : pt.element;
        r.uniform = g.storage == spv::StorageClassUniform && !m.decor(block).bufferBlock;
        g.slot = int(info.resources.size());
        info.resources.push_back(r);
        break;
      }
      case spv::StorageClassUniformConstant: {
        // Images, samplers and combined image samplers (possibly arrays of them): descriptors.
        if (!named.count(id)) break;
        const Type& inner = spvType(pt.element);
        bool arrayed = inner.kind == Type::Array || inner.kind == Type::RuntimeArray;
        uint32_t elem = arrayed ? inner.element : pt.element;
        const Instruction* ti = m.def(elem);
        if (!ti || (!isImageLike(elem) && !isAccelerationStructure(elem))) break;  // fails when used
        ResourceBinding r;
        r.set = uint32_t(std::max(d.set, 0));
        r.binding = uint32_t(std::max(d.binding, 0));
        r.arraySize = inner.kind == Type::Array ? inner.count : inner.kind == Type::RuntimeArray ? 0 : 1;
        r.uniform = false;
        if (ti->op == spv::OpTypeAccelerationStructureKHR)
          r.kind = ResourceBinding::AccelerationStructure;
        else if (ti->op == spv::OpTypeSampler)
          r.kind = ResourceBinding::Sampler;
        else if (ti->op == spv::OpTypeSampledImage)
          r.kind =
              isTexelBuffer(ti->word(2)) ? ResourceBinding::UniformTexelBuffer : ResourceBinding::CombinedImageSampler;
        else if (ti->op == spv::OpTypeImage && ti->word(3) == spv::DimSubpassData)
          r.kind = ResourceBinding::InputAttachment;
        else if (isTexelBuffer(elem))
          r.kind = ti->word(7) == 2 ? ResourceBinding::StorageTexelBuffer : ResourceBinding::UniformTexelBuffer;
        else
          r.kind = ti->word(7) == 2 ? ResourceBinding::StorageImage : ResourceBinding::SampledImage;
        g.slot = int(info.resources.size());
        info.resources.push_back(r);
        break;
      }
      default: break;  // PushConstant needs nothing; other classes fail when used
    }
    globals[id] = g;
  }
  info.workgroupMemorySize = uint32_t(workgroupSize);
  return true;
}

// Loads a pointer-sized field of the invocation context.
static llvm::Value* ctxField(Codegen& g, unsigned offset) {
  return g.b.CreateAlignedLoad(g.b.getPtrTy(), g.b.CreateConstGEP1_64(g.b.getInt8Ty(), g.ctxArg, offset),
                               llvm::Align(8));
}

// Descriptor tables and records do not change while a dispatch runs (shaders cannot write them): marked
// invariant, their loads can leave the per-workgroup loop although the shader stores to buffers in it.
static llvm::Value* invariant(llvm::LoadInst* load) {
  load->setMetadata(llvm::LLVMContext::MD_invariant_load, llvm::MDNode::get(load->getContext(), {}));
  return load;
}

void Codegen::reportDescriptorIndex(const Ptr& p, llvm::Value* index, llvm::Value* count) {
  llvm::Function* f = b.GetInsertBlock()->getParent();
  auto* report = llvm::BasicBlock::Create(c, "descriptor.outofbounds", f);
  auto* join = llvm::BasicBlock::Create(c, "descriptor.inbounds", f);
  b.CreateCondBr(b.CreateICmpULT(index, count), join, report, llvm::MDBuilder(c).createBranchWeights(1u << 20, 1));
  b.SetInsertPoint(report);
  outOfBounds(p, abi::kAccessDescriptorIndex, 0, index, count, index);
  b.CreateBr(join);
  b.SetInsertPoint(join);
}

llvm::Value* Codegen::descriptorRecord(int slot, llvm::Value* index, const Ptr* site) {
  llvm::Value* table = ctxField(*this, offsetof(InvocationContext, resources));
  llvm::Value* entry = b.CreateConstGEP1_64(b.getInt8Ty(), table, uint64_t(slot) * sizeof(ResourceSlot));
  llvm::Value* records = invariant(b.CreateAlignedLoad(b.getPtrTy(), entry, llvm::Align(8)));
  llvm::Value* count =
      invariant(b.CreateAlignedLoad(b.getInt64Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), entry, 8), llvm::Align(8)));
  index = b.CreateZExtOrTrunc(index, b.getInt64Ty());
  if (site && site->resource >= 0 && !b.GetInsertBlock()->getTerminator()) reportDescriptorIndex(*site, index, count);
  // An index past the bound descriptors reads a null descriptor (a zero record).
  llvm::Value* rec = b.CreateGEP(b.getInt8Ty(), records, b.CreateMul(index, i64(sizeof(DescriptorRecord))));
  return b.CreateSelect(b.CreateICmpULT(index, count), rec, zeros);
}

bool Codegen::resolveDescriptor(Ptr& p, llvm::Value* index) {
  llvm::Value* table = ctxField(*this, offsetof(InvocationContext, resources));
  llvm::Value* entry = b.CreateConstGEP1_64(b.getInt8Ty(), table, uint64_t(p.slot) * sizeof(ResourceSlot));
  llvm::Value* records = invariant(b.CreateAlignedLoad(b.getPtrTy(), entry, llvm::Align(8)));
  llvm::Value* count =
      invariant(b.CreateAlignedLoad(b.getInt64Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), entry, 8), llvm::Align(8)));
  index = b.CreateZExtOrTrunc(index, b.getInt64Ty());
  // An index past the bound descriptors reads a null descriptor: every access through it is out of bounds.
  llvm::Value* ok = b.CreateICmpULT(index, count);
  p.element = index;
  if (p.resource >= 0 && !b.GetInsertBlock()->getTerminator()) reportDescriptorIndex(p, index, count);
  llvm::Value* rec = b.CreateGEP(b.getInt8Ty(), records, b.CreateMul(index, i64(sizeof(DescriptorRecord))));
  rec = b.CreateSelect(ok, rec, zeros);
  llvm::Value* address = invariant(b.CreateAlignedLoad(b.getInt64Ty(), rec, llvm::Align(8)));
  llvm::Value* range =
      invariant(b.CreateAlignedLoad(b.getInt64Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), rec, 8), llvm::Align(8)));
  const Type& t = spvType(p.type);
  p.base = b.CreateIntToPtr(address, b.getPtrTy());
  p.offset = i64(0);
  p.limit = range;
  p.type = (t.kind == Type::Array || t.kind == Type::RuntimeArray) ? t.element : p.type;
  p.slot = -1;
  return true;
}

bool Codegen::variablePtr(uint32_t id, Ptr* out) {
  const Instruction* in = m.def(id);
  auto git = globals.find(id);
  if (!in || git == globals.end()) return false;
  const Global& g = git->second;
  const Type& pt = spvType(in->word(1));
  // Module-scope pointers are computed once, at the top of the function.
  llvm::IRBuilderBase::InsertPointGuard guard(b);
  if (allocaBlock->getTerminator()) {
    b.SetInsertPoint(allocaBlock->getTerminator());
  } else {
    b.SetInsertPoint(allocaBlock);
  }
  Ptr p;
  p.type = pt.element;
  p.storage = g.storage;
  p.offset = i64(0);
  if (g.graphicsField >= 0 || g.inPrivate) {
    // A vertex / fragment built-in in place, or an interface variable's copy in the private block.
    if (g.inPrivate) {
      p.base = b.CreateConstGEP1_64(b.getInt8Ty(), privArg, g.offset);
    } else {
      p.base = b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, unsigned(g.graphicsField));
    }
    p.limit = i64(g.size);
    *out = p;
    return true;
  }
  if (g.contextField >= 0) {
    // A block the runtime provides: {pointer, byte count} in the RayInvocation.
    if (!isRayTracing()) return unsupported(*in, "ray tracing storage class outside a ray tracing stage");
    p.base = ctxField(*this, unsigned(g.contextField));
    p.limit = b.CreateAlignedLoad(
        b.getInt64Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, unsigned(g.contextField) + 8), llvm::Align(8));
    *out = p;
    return true;
  }
  switch (g.storage) {
    case spv::StorageClassPrivate:
    case spv::StorageClassRayPayloadKHR:
    case spv::StorageClassCallableDataKHR:
    case spv::StorageClassHitAttributeKHR:
      if (!isRayTracing() && g.storage != spv::StorageClassPrivate)
        return unsupported(*in, "ray tracing storage class outside a ray tracing stage");
      p.base = b.CreateConstGEP1_64(b.getInt8Ty(), privArg, g.offset);
      p.limit = i64(g.size);
      break;
    case spv::StorageClassWorkgroup:
      p.base =
          b.CreateConstGEP1_64(b.getInt8Ty(), ctxField(*this, offsetof(InvocationContext, workgroupMemory)), g.offset);
      p.limit = i64(g.size);
      break;
    case spv::StorageClassPushConstant:
      p.base = ctxField(*this, offsetof(InvocationContext, pushConstants));
      p.limit = i64(kPushConstantBytes);
      break;
    case spv::StorageClassInput: {
      if (g.builtIn == spv::BuiltInDeviceIndex ||
          (g.builtIn == spv::BuiltInSubgroupLocalInvocationId && !isRayTracing())) {
        // One physical device per logical device, and subgroups of one invocation (VkPhysicalDeviceSubgroupProperties):
        // the device index and the index within the subgroup are always 0 (read from the zero sink).
        p.base = zeros;
        p.limit = i64(4);
        break;
      }
      if ((g.builtIn == spv::BuiltInSubgroupSize || g.builtIn == spv::BuiltInNumSubgroups) && !isRayTracing()) {
        // Subgroups of one invocation: a workgroup has as many subgroups as invocations.
        uint32_t v = 1;
        if (g.builtIn == spv::BuiltInNumSubgroups) v = info.localSize[0] * info.localSize[1] * info.localSize[2];
        p.base =
            new llvm::GlobalVariable(this->out, b.getInt32Ty(), true, llvm::GlobalValue::PrivateLinkage, b.getInt32(v));
        p.limit = i64(4);
        break;
      }
      uint32_t size = 0;
      int off = builtInOffset(g.builtIn, isRayTracing(), &size);
      if (off < 0)
        return unsupported(*in, g.builtIn >= 0 ? "built-in variable not supported in this stage" : "input variable");
      p.base = b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, unsigned(off));
      p.limit = i64(size);
      break;
    }
    case spv::StorageClassUniformConstant:
      if (g.slot < 0)
        return unsupported(*in, "UniformConstant variable that is not an image, sampler or acceleration structure");
      p.slot = g.slot;
      p.resource = g.slot;
      p.variable = id;
      break;
    case spv::StorageClassUniform:
    case spv::StorageClassStorageBuffer: {
      p.slot = g.slot;
      p.resource = g.slot;
      p.variable = id;
      const Type& inner = spvType(pt.element);
      if (inner.kind != Type::Array && inner.kind != Type::RuntimeArray) resolveDescriptor(p, i64(0));
      break;
    }
    default: return unsupported(*in, "storage class");
  }
  *out = p;
  return true;
}

Ptr& Codegen::ptr(uint32_t id) {
  auto it = ptrs.find(id);
  if (it != ptrs.end()) return it->second;
  Ptr p;
  if (globals.count(id) && variablePtr(id, &p)) return ptrs[id] = p;
  // A PhysicalStorageBuffer pointer value (a device address, which in vkrt is the host address): unbounded,
  // as on any device (an invalid address is the application's undefined behaviour).
  const Type& pt = spvType(m.typeOf(id));
  if (pt.kind == Type::Pointer && pt.storage == spv::StorageClassPhysicalStorageBuffer) {
    if (llvm::Value* v = value(id)) {
      p.base = v;
      p.offset = i64(0);
      p.limit = i64(1ull << 62);
      p.type = pt.element;
      p.storage = pt.storage;
      return ptrs[id] = p;
    }
  }
  static thread_local Ptr none;
  none = Ptr{};
  return none;
}

llvm::Value* Codegen::inBounds(const Ptr& p, uint64_t bytes, uint32_t kind) {
  llvm::Value* ok = nullptr;
  auto* co = llvm::dyn_cast<llvm::ConstantInt>(p.offset);
  auto* cl = llvm::dyn_cast<llvm::ConstantInt>(p.limit);
  if (!(co && cl && cl->getZExtValue() >= bytes && co->getZExtValue() <= cl->getZExtValue() - bytes)) {
    // offset + bytes <= limit without overflow: offset < limit - (bytes - 1), the subtraction saturating at 0
    // (nothing fits in a smaller limit). One comparison with a value that is invariant where the limit is.
    llvm::Value* end = b.CreateBinaryIntrinsic(llvm::Intrinsic::usub_sat, p.limit, i64(bytes ? bytes - 1 : 0));
    ok = b.CreateICmpULT(p.offset, end);
  }
  // A device address has no limit of its own (1 << 62): VKRT_SHADER_CHECKS=bda checks it against the live buffers.
  if (p.storage == spv::StorageClassPhysicalStorageBuffer && (checks & abi::kCheckDeviceAddress))
    return checkAddress(p, bytes, kind, ok);
  return ok;
}

llvm::Value* Codegen::address(const Ptr& p, uint64_t bytes, bool write, uint32_t kind) {
  llvm::Value* real = b.CreateGEP(b.getInt8Ty(), p.base, p.offset);
  llvm::Value* ok = inBounds(p, bytes, kind != ~0u ? kind : write ? abi::kAccessAtomic : abi::kAccessLoad);
  if (!ok) return real;
  if (write && !b.GetInsertBlock()->getTerminator()) {
    // An atomic: the failing branch reports it, then both go on to the select below.
    auto* join = llvm::BasicBlock::Create(c, "atomic.join", b.GetInsertBlock()->getParent());
    if (llvm::BasicBlock* report = outOfBoundsBlock(p, abi::kAccessAtomic, bytes, join)) {
      b.CreateCondBr(ok, join, report, llvm::MDBuilder(c).createBranchWeights(1u << 20, 1));
      b.SetInsertPoint(join);
    } else {
      join->eraseFromParent();
    }
  }
  llvm::Value* fallback = write ? ctxField(*this, offsetof(InvocationContext, sink)) : static_cast<llvm::Value*>(zeros);
  return b.CreateSelect(ok, real, fallback);
}

// Branches on `ok` to a new block, where the builder is left; returns the block that the access skips to, which
// the caller enters once the access is emitted.
// `failed` is set to the block the failing branch comes from into the join: the report's (a buffer reached through
// a descriptor: Codegen::outOfBoundsBlock) or the branch's own.
static llvm::BasicBlock* beginGuarded(Codegen& g, llvm::Value* ok, const Ptr& p, uint32_t kind, uint64_t bytes,
                                      llvm::BasicBlock** failed) {
  llvm::Function* f = g.b.GetInsertBlock()->getParent();
  *failed = g.b.GetInsertBlock();
  auto* then = llvm::BasicBlock::Create(g.c, "inbounds", f);
  auto* join = llvm::BasicBlock::Create(g.c, "inbounds.join", f);
  llvm::BasicBlock* report = g.outOfBoundsBlock(p, kind, bytes, join, failed);
  // Out-of-bounds accesses are the exception: the weights make the in-bounds path the straight one.
  g.b.CreateCondBr(ok, then, report ? report : join, llvm::MDBuilder(g.c).createBranchWeights(1u << 20, 1));
  g.b.SetInsertPoint(then);
  return join;
}

// A load that reads zeros out of bounds. It branches around the load rather than selecting the address, so
// that a loop of such loads keeps consecutive addresses: LLVM can vectorize it with masked loads.
llvm::Value* Codegen::guardedLoad(const Ptr& p, llvm::Type* ty, uint64_t bytes, llvm::Align align) {
  // Where the block is closed already (code placed before its terminator), the address is selected instead.
  bool closed = b.GetInsertBlock()->getTerminator() != nullptr;
  flushOverlappingAdds(p, bytes);
  // A shader record read is checked against the SBT region (not in a closed block: no branch can be placed there).
  if (p.storage == spv::StorageClassShaderRecordBufferKHR && !closed) checkShaderRecordRead(p, bytes);
  llvm::Value* ok = closed ? nullptr : inBounds(p, bytes);
  if (!ok) {
    return b.CreateAlignedLoad(ty, closed ? address(p, bytes, false) : b.CreateGEP(b.getInt8Ty(), p.base, p.offset),
                               align);
  }
  llvm::BasicBlock* from = nullptr;
  llvm::BasicBlock* join = beginGuarded(*this, ok, p, abi::kAccessLoad, bytes, &from);
  llvm::LoadInst* l = b.CreateAlignedLoad(ty, b.CreateGEP(b.getInt8Ty(), p.base, p.offset), align);
  llvm::BasicBlock* then = b.GetInsertBlock();
  b.CreateBr(join);
  b.SetInsertPoint(join);
  llvm::PHINode* phi = b.CreatePHI(ty, 2);
  phi->addIncoming(l, then);
  phi->addIncoming(llvm::Constant::getNullValue(ty), from);
  return phi;
}

// A store that is dropped out of bounds (a branch around it, see guardedLoad).
void Codegen::guardedStore(const Ptr& p, llvm::Value* v, uint64_t bytes, llvm::Align align) {
  bool closed = b.GetInsertBlock()->getTerminator() != nullptr;
  flushOverlappingAdds(p, bytes);
  llvm::Value* ok = closed ? nullptr : inBounds(p, bytes, abi::kAccessStore);
  if (!ok) {
    b.CreateAlignedStore(
        v, closed ? address(p, bytes, true, abi::kAccessStore) : b.CreateGEP(b.getInt8Ty(), p.base, p.offset), align);
    return;
  }
  llvm::BasicBlock* failed = nullptr;
  llvm::BasicBlock* join = beginGuarded(*this, ok, p, abi::kAccessStore, bytes, &failed);
  b.CreateAlignedStore(v, b.CreateGEP(b.getInt8Ty(), p.base, p.offset), align);
  b.CreateBr(join);
  b.SetInsertPoint(join);
}

static Ptr offsetBy(const Ptr& p, Codegen& g, uint64_t bytes, uint32_t type) {
  Ptr q = p;
  q.offset = g.b.CreateAdd(p.offset, g.i64(bytes));
  q.type = type;
  return q;
}

llvm::Value* Codegen::load(const Ptr& p) {
  const Type& t = spvType(p.type);
  llvm::Type* ty = type(p.type);
  if (!ty) return nullptr;
  switch (t.kind) {
    case Type::Bool: return b.CreateICmpNE(guardedLoad(p, b.getInt32Ty(), 4, llvm::Align(4)), i32(0));
    case Type::Int:
    case Type::Float: {
      // Push constants are not marked invariant: in vkrt_group they are read from the workgroup's local copy,
      // which is written (memcpy) before the loop, and an invariant load would let LLVM drop that copy as dead
      // where the index is not constant (an 8-bit array indexed by the invocation read zeros). Loads from the
      // unescaped copy leave the loop without it.
      return guardedLoad(p, ty, t.width / 8, llvm::Align(t.width / 8));
    }
    case Type::Pointer:
      if (t.storage != spv::StorageClassPhysicalStorageBuffer) return nullptr;
      return guardedLoad(p, b.getPtrTy(), 8, llvm::Align(8));
    case Type::Vector: {
      uint64_t cs = layoutSize(t.element, 0, false);
      bool isBool = spvType(t.element).kind == Type::Bool;
      if (p.vecStride == 0 || p.vecStride == cs) {
        llvm::Type* memTy = isBool ? llvm::FixedVectorType::get(b.getInt32Ty(), t.count) : ty;
        llvm::Value* v = guardedLoad(p, memTy, cs * t.count, llvm::Align(cs));
        return isBool ? b.CreateICmpNE(v, llvm::Constant::getNullValue(memTy)) : v;
      }
      llvm::Value* v = llvm::UndefValue::get(ty);
      for (uint32_t i = 0; i < t.count; ++i) {
        Ptr q = offsetBy(p, *this, uint64_t(i) * p.vecStride, t.element);
        q.vecStride = 0;
        v = b.CreateInsertElement(v, load(q), uint64_t(i));
      }
      return v;
    }
    case Type::Matrix: {
      uint32_t stride = p.matrixStride ? p.matrixStride : naturalMatrixStride(p.type);
      uint64_t cs = layoutSize(scalarType(t.element), 0, false);
      llvm::Value* v = llvm::UndefValue::get(ty);
      for (uint32_t i = 0; i < t.count; ++i) {
        Ptr q = offsetBy(p, *this, p.rowMajor ? i * cs : uint64_t(i) * stride, t.element);
        q.vecStride = p.rowMajor ? stride : 0;
        v = b.CreateInsertValue(v, load(q), {i});
      }
      return v;
    }
    case Type::Array: {
      uint64_t stride = arrayStride(p.type, p.matrixStride, p.rowMajor);
      llvm::Value* v = llvm::UndefValue::get(ty);
      for (uint32_t i = 0; i < t.count; ++i) {
        llvm::Value* e = load(offsetBy(p, *this, i * stride, t.element));
        if (!e) return nullptr;
        v = b.CreateInsertValue(v, e, {i});
      }
      return v;
    }
    case Type::Struct: {
      llvm::Value* v = llvm::UndefValue::get(ty);
      for (uint32_t i = 0; i < t.members.size(); ++i) {
        const Decorations& d = m.memberDecor(p.type, i);
        Ptr q = offsetBy(p, *this, memberOffset(p.type, i), t.members[i]);
        q.matrixStride = d.matrixStride > 0 ? uint32_t(d.matrixStride) : 0;
        q.rowMajor = d.rowMajor;
        llvm::Value* e = load(q);
        if (!e) return nullptr;
        v = b.CreateInsertValue(v, e, {i});
      }
      return v;
    }
    default: return nullptr;
  }
}

void Codegen::store(const Ptr& p, llvm::Value* v) {
  const Type& t = spvType(p.type);
  switch (t.kind) {
    case Type::Bool: guardedStore(p, b.CreateZExt(v, b.getInt32Ty()), 4, llvm::Align(4)); return;
    case Type::Int:
    case Type::Float: guardedStore(p, v, t.width / 8, llvm::Align(t.width / 8)); return;
    case Type::Pointer: guardedStore(p, v, 8, llvm::Align(8)); return;
    case Type::Vector: {
      uint64_t cs = layoutSize(t.element, 0, false);
      bool isBool = spvType(t.element).kind == Type::Bool;
      if (p.vecStride == 0 || p.vecStride == cs) {
        if (isBool) v = b.CreateZExt(v, llvm::FixedVectorType::get(b.getInt32Ty(), t.count));
        guardedStore(p, v, cs * t.count, llvm::Align(cs));
        return;
      }
      for (uint32_t i = 0; i < t.count; ++i) {
        Ptr q = offsetBy(p, *this, uint64_t(i) * p.vecStride, t.element);
        q.vecStride = 0;
        store(q, b.CreateExtractElement(v, uint64_t(i)));
      }
      return;
    }
    case Type::Matrix: {
      uint32_t stride = p.matrixStride ? p.matrixStride : naturalMatrixStride(p.type);
      uint64_t cs = layoutSize(scalarType(t.element), 0, false);
      for (uint32_t i = 0; i < t.count; ++i) {
        Ptr q = offsetBy(p, *this, p.rowMajor ? i * cs : uint64_t(i) * stride, t.element);
        q.vecStride = p.rowMajor ? stride : 0;
        store(q, b.CreateExtractValue(v, {i}));
      }
      return;
    }
    case Type::Array: {
      uint64_t stride = arrayStride(p.type, p.matrixStride, p.rowMajor);
      for (uint32_t i = 0; i < t.count; ++i)
        store(offsetBy(p, *this, i * stride, t.element), b.CreateExtractValue(v, {i}));
      return;
    }
    case Type::Struct:
      for (uint32_t i = 0; i < t.members.size(); ++i) {
        const Decorations& d = m.memberDecor(p.type, i);
        Ptr q = offsetBy(p, *this, memberOffset(p.type, i), t.members[i]);
        q.matrixStride = d.matrixStride > 0 ? uint32_t(d.matrixStride) : 0;
        q.rowMajor = d.rowMajor;
        store(q, b.CreateExtractValue(v, {i}));
      }
      return;
    default: return;
  }
}

// A pointer operand (checked: the id must be a pointer this compiler tracks).
static bool operandPtr(Codegen& g, const Instruction& in, uint32_t id, Ptr* out) {
  Ptr& p = g.ptr(id);
  if (!p.base && p.slot < 0)
    return g.unsupported(in, "pointer operand the compiler does not track (variable pointers?)");
  *out = p;
  return true;
}

bool Codegen::memory(const Instruction& in, bool& ok) {
  if (rayQueryValue(in, ok)) return true;  // OpLoad / OpStore of a whole ray query (ray_query.cpp)
  switch (in.op) {
    case spv::OpVariable: {
      // Function-scope variable: bytes in the function's entry block.
      const Type& pt = spvType(in.word(1));
      if (pt.storage != spv::StorageClassFunction) return (ok = unsupported(in, "storage class in a function")), true;
      uint64_t size = std::max<uint64_t>(layoutSize(pt.element, 0, false), 1);
      llvm::IRBuilderBase::InsertPointGuard guard(b);
      b.SetInsertPoint(allocaBlock->getTerminator());
      auto* a = b.CreateAlloca(b.getInt8Ty(), i64(size));
      a->setAlignment(llvm::Align(16));
      if (isRayQuery(pt.element)) b.CreateMemSet(a, b.getInt8(0), i64(size), llvm::MaybeAlign(16));  // not begun
      Ptr p;
      p.base = a;
      p.offset = i64(0);
      p.limit = i64(size);
      p.type = pt.element;
      ptrs[in.word(2)] = p;
      if (in.count > 4) {
        llvm::Value* init = value(in.word(4));
        if (!init) return (ok = fail(in, "variable initializer is not a constant")), true;
        store(p, init);
      }
      return true;
    }
    case spv::OpAccessChain:
    case spv::OpInBoundsAccessChain:
    case spv::OpPtrAccessChain:
    case spv::OpInBoundsPtrAccessChain: return accessChain(in, ok);
    case spv::OpConvertUToPtr: {
      llvm::Value* v = value(in.word(3));
      if (!v) return (ok = fail(in, "operand has no value")), true;
      set(in.word(2), b.CreateIntToPtr(b.CreateZExtOrTrunc(v, b.getInt64Ty()), b.getPtrTy()));
      return true;
    }
    case spv::OpConvertPtrToU: {
      llvm::Value* v = value(in.word(3));
      llvm::Type* rt = type(in.word(1));
      if (!v || !rt)
        return (ok = unsupported(in, "pointer operand without a value (not a PhysicalStorageBuffer pointer?)")), true;
      set(in.word(2), b.CreatePtrToInt(v, rt));
      return true;
    }
    case spv::OpLoad: {
      Ptr p;
      if (!operandPtr(*this, in, in.word(3), &p)) return (ok = false), true;
      if (p.slot >= 0 && p.storage == spv::StorageClassUniformConstant) {
        llvm::Value* rec = descriptorRecord(p.slot, p.descIndex ? p.descIndex : i64(0), p.descIndex ? &p : nullptr);
        if (isAccelerationStructure(p.type)) {
          // An acceleration structure is its device address (the record's first field).
          set(in.word(2), invariant(b.CreateAlignedLoad(b.getInt64Ty(), rec, llvm::Align(8))));
          return true;
        }
        // An image, sampler or combined image sampler: its descriptor record, twice (see imageValueType()).
        if (!isImageLike(p.type)) return (ok = unsupported(in, "load of a whole descriptor array")), true;
        llvm::Value* v = llvm::UndefValue::get(imageValueType());
        v = b.CreateInsertValue(v, rec, {0});
        set(in.word(2), b.CreateInsertValue(v, rec, {1}));
        return true;
      }
      if (p.slot >= 0) return (ok = unsupported(in, "load of a whole descriptor array")), true;
      llvm::Value* v = load(p);
      if (!v) return (ok = unsupported(in, "loaded type")), true;
      set(in.word(2), v);
      return true;
    }
    case spv::OpStore: {
      Ptr p;
      if (!operandPtr(*this, in, in.word(1), &p)) return (ok = false), true;
      llvm::Value* v = value(in.word(2));
      if (!v || p.slot >= 0 || !type(p.type)) return (ok = unsupported(in, "stored value")), true;
      store(forWrite(p), v);
      return true;
    }
    case spv::OpCopyMemory: {
      Ptr dst, src;
      if (!operandPtr(*this, in, in.word(1), &dst) || !operandPtr(*this, in, in.word(2), &src))
        return (ok = false), true;
      llvm::Value* v = (src.slot < 0) ? load(src) : nullptr;
      if (!v || dst.slot >= 0) return (ok = unsupported(in, "copied type")), true;
      store(forWrite(dst), v);
      return true;
    }
    case spv::OpPtrEqual:
    case spv::OpPtrNotEqual: {
      // SPIR-V 1.4. Without variable pointers a Vulkan module may compare StorageBuffer pointers only under the
      // PhysicalStorageBuffer64 addressing model; whatever the class, two pointers are equal when they address
      // the same byte (a pointer into a descriptor array not indexed yet has no address: refused).
      Ptr x, y;
      if (!operandPtr(*this, in, in.word(3), &x) || !operandPtr(*this, in, in.word(4), &y)) return (ok = false), true;
      if (x.slot >= 0 || y.slot >= 0) return (ok = unsupported(in, "comparison of descriptor array pointers")), true;
      llvm::Value* ax = b.CreatePtrToInt(b.CreateGEP(b.getInt8Ty(), x.base, x.offset), b.getInt64Ty());
      llvm::Value* ay = b.CreatePtrToInt(b.CreateGEP(b.getInt8Ty(), y.base, y.offset), b.getInt64Ty());
      set(in.word(2), in.op == spv::OpPtrEqual ? b.CreateICmpEQ(ax, ay) : b.CreateICmpNE(ax, ay));
      return true;
    }
    case spv::OpArrayLength: {
      Ptr p;
      if (!operandPtr(*this, in, in.word(3), &p)) return (ok = false), true;
      const Type& st = spvType(p.type);
      uint32_t member = in.word(4);
      if (p.slot >= 0 || st.kind != Type::Struct || member >= st.members.size())
        return (ok = fail(in, "bad OpArrayLength operand")), true;
      llvm::Value* start = b.CreateAdd(p.offset, i64(memberOffset(p.type, member)));
      llvm::Value* stride = i64(arrayStride(st.members[member], 0, false));
      llvm::Value* bytes = b.CreateSelect(b.CreateICmpUGT(p.limit, start), b.CreateSub(p.limit, start), i64(0));
      set(in.word(2), b.CreateTrunc(b.CreateUDiv(bytes, stride), b.getInt32Ty()));
      return true;
    }
    default: return atomicOp(in.op) ? atomic(in, ok) : false;
  }
}

// OpAccessChain, OpInBoundsAccessChain, OpPtrAccessChain, OpInBoundsPtrAccessChain (Codegen::memory).
bool Codegen::accessChain(const Instruction& in, bool& ok) {
  Ptr p;
  if (!operandPtr(*this, in, in.word(3), &p)) return (ok = false), true;
  bool ptrChain = in.op == spv::OpPtrAccessChain || in.op == spv::OpInBoundsPtrAccessChain;
  uint32_t firstIndex = 4;
  if (ptrChain) {
    // The Element operand steps over whole pointees by the pointer type's ArrayStride.
    const Decorations& pd = m.decor(m.typeOf(in.word(3)));
    llvm::Value* e = value(in.word(4));
    if (!e || pd.arrayStride <= 0 || p.slot >= 0)
      return (ok = unsupported(in, "element index without an ArrayStride")), true;
    e = isSignedInt(m.typeOf(in.word(4))) ? b.CreateSExtOrTrunc(e, b.getInt64Ty())
                                          : b.CreateZExtOrTrunc(e, b.getInt64Ty());
    p.offset = b.CreateAdd(p.offset, b.CreateMul(e, i64(uint64_t(pd.arrayStride))));
    firstIndex = 5;
  }
  for (uint32_t i = firstIndex; i < in.count; ++i) {
    uint32_t idx = in.word(i);
    if (p.slot >= 0 && p.storage == spv::StorageClassUniformConstant) {
      // An element of an image/sampler descriptor array.
      llvm::Value* iv = value(idx);
      const Type& at = spvType(p.type);
      if (!iv || p.descIndex || (at.kind != Type::Array && at.kind != Type::RuntimeArray))
        return (ok = fail(in, "bad index into an image or sampler descriptor array")), true;
      p.descIndex = b.CreateZExtOrTrunc(iv, b.getInt64Ty());
      p.type = at.element;
      continue;
    }
    if (p.slot >= 0) {
      llvm::Value* iv = value(idx);
      if (!iv) return (ok = fail(in, "descriptor index has no value")), true;
      resolveDescriptor(p, iv);
      continue;
    }
    const Type& t = spvType(p.type);
    uint64_t k = 0;
    bool isConst = m.constantU64(idx, &k);
    llvm::Value* iv = nullptr;
    if (!isConst) {
      iv = value(idx);
      if (!iv) return (ok = fail(in, "index has no value")), true;
      iv = isSignedInt(m.typeOf(idx)) ? b.CreateSExtOrTrunc(iv, b.getInt64Ty())
                                      : b.CreateZExtOrTrunc(iv, b.getInt64Ty());
    } else {
      iv = i64(k);
      if (isSignedInt(m.constant(idx)->type) && spvType(m.constant(idx)->type).width < 64) {
        uint32_t w = spvType(m.constant(idx)->type).width;
        if (k >> (w - 1)) k |= ~((1ull << w) - 1);
        iv = i64(k);
      }
    }
    switch (t.kind) {
      case Type::Struct: {
        if (!isConst || k >= t.members.size()) return (ok = fail(in, "struct index is not a valid constant")), true;
        const Decorations& d = m.memberDecor(p.type, uint32_t(k));
        p.offset = b.CreateAdd(p.offset, i64(memberOffset(p.type, uint32_t(k))));
        p.type = t.members[k];
        p.matrixStride = d.matrixStride > 0 ? uint32_t(d.matrixStride) : 0;
        p.rowMajor = d.rowMajor;
        p.vecStride = 0;
        break;
      }
      case Type::Array:
      case Type::RuntimeArray:
        p.offset = b.CreateAdd(p.offset, b.CreateMul(iv, i64(arrayStride(p.type, p.matrixStride, p.rowMajor))));
        p.type = t.element;
        break;
      case Type::Matrix: {
        uint32_t stride = p.matrixStride ? p.matrixStride : naturalMatrixStride(p.type);
        uint64_t cs = layoutSize(scalarType(t.element), 0, false);
        p.offset = b.CreateAdd(p.offset, b.CreateMul(iv, i64(p.rowMajor ? cs : stride)));
        p.vecStride = p.rowMajor ? stride : 0;
        p.type = t.element;
        break;
      }
      case Type::Vector: {
        uint64_t cs = layoutSize(t.element, 0, false);
        p.offset = b.CreateAdd(p.offset, b.CreateMul(iv, i64(p.vecStride ? p.vecStride : cs)));
        p.vecStride = 0;
        p.type = t.element;
        break;
      }
      default: return (ok = fail(in, "access chain indexes a non-composite")), true;
    }
  }
  ptrs[in.word(2)] = p;
  // A PhysicalStorageBuffer pointer is also a value (it may be stored, converted or compared).
  if (p.storage == spv::StorageClassPhysicalStorageBuffer)
    set(in.word(2), b.CreateGEP(b.getInt8Ty(), p.base, p.offset));
  return true;
}

// ---- combined counter adds (abi::PendingAdds)

namespace {

constexpr unsigned kPendingBegin = offsetof(abi::PendingAdds, begin), kPendingEnd = offsetof(abi::PendingAdds, end),
                   kPendingSum = offsetof(abi::PendingAdds, sum), kPendingFlush = offsetof(abi::PendingAdds, flush);

// The module's internal helper `name` (always inlined): made by `build` on first use, with its own builder, so
// that the caller's insertion point (a closed block too) is left as it is.
template <class Build>
llvm::Function* helper(Codegen& g, const char* name, llvm::FunctionType* ft, Build build) {
  if (llvm::Function* f = g.out.getFunction(name)) return f;
  auto* f = llvm::Function::Create(ft, llvm::GlobalValue::InternalLinkage, name, g.out);
  f->addFnAttr(llvm::Attribute::AlwaysInline);
  f->addFnAttr(llvm::Attribute::NoUnwind);
  llvm::IRBuilder<> h(llvm::BasicBlock::Create(g.c, "entry", f));
  build(h, f);
  return f;
}

llvm::Value* pendingField(llvm::IRBuilder<>& h, llvm::Value* adds, unsigned offset, llvm::Type* ty) {
  return h.CreateAlignedLoad(ty, h.CreateConstGEP1_64(h.getInt8Ty(), adds, offset), llvm::Align(8));
}
void setPendingField(llvm::IRBuilder<>& h, llvm::Value* adds, unsigned offset, llvm::Value* v) {
  h.CreateAlignedStore(v, h.CreateConstGEP1_64(h.getInt8Ty(), adds, offset), llvm::Align(8));
}
// adds->flush(adds), at h.
void callFlush(llvm::IRBuilder<>& h, llvm::Value* adds) {
  llvm::Value* fn = pendingField(h, adds, kPendingFlush, h.getPtrTy());
  h.CreateCall(llvm::FunctionType::get(h.getVoidTy(), {h.getPtrTy()}, false), fn, {adds});
}

// Rarely taken: a flush.
llvm::MDNode* unlikely(Codegen& g) { return llvm::MDBuilder(g.c).createBranchWeights(1, 1u << 20); }

// vkrt.pending.overlap(adds, address, bytes): flushes when [address, address + bytes) overlaps the pending word.
llvm::Function* overlapHelper(Codegen& g) {
  auto* i64 = llvm::Type::getInt64Ty(g.c);
  auto* ptr = llvm::PointerType::get(g.c, 0);
  auto* ft = llvm::FunctionType::get(llvm::Type::getVoidTy(g.c), {ptr, i64, i64}, false);
  return helper(g, "vkrt.pending.overlap", ft, [&](llvm::IRBuilder<>& h, llvm::Function* f) {
    llvm::Value *adds = f->getArg(0), *at = f->getArg(1), *bytes = f->getArg(2);
    auto* test = llvm::BasicBlock::Create(g.c, "test", f);
    auto* flush = llvm::BasicBlock::Create(g.c, "flush", f);
    auto* done = llvm::BasicBlock::Create(g.c, "done", f);
    h.CreateCondBr(h.CreateIsNull(adds), done, test);
    h.SetInsertPoint(test);
    llvm::Value* begin = pendingField(h, adds, kPendingBegin, i64);
    llvm::Value* end = pendingField(h, adds, kPendingEnd, i64);
    llvm::Value* overlaps = h.CreateAnd(h.CreateICmpULT(at, end), h.CreateICmpULT(begin, h.CreateAdd(at, bytes)));
    h.CreateCondBr(overlaps, flush, done, unlikely(g));
    h.SetInsertPoint(flush);
    callFlush(h, adds);
    h.CreateBr(done);
    h.SetInsertPoint(done);
    h.CreateRetVoid();
  });
}

// vkrt.pending.add.iN(adds, address, value): value added to the pending sum of the word at address (the pending
// word flushed first when it is another), or atomically where the invocation has no table.
llvm::Function* pendingAddHelper(Codegen& g, llvm::Type* ty) {
  const uint64_t bytes = ty->getIntegerBitWidth() / 8;
  auto* i64 = llvm::Type::getInt64Ty(g.c);
  auto* ptr = llvm::PointerType::get(g.c, 0);
  auto* ft = llvm::FunctionType::get(llvm::Type::getVoidTy(g.c), {ptr, ptr, ty}, false);
  const char* name = bytes == 8 ? "vkrt.pending.add.i64" : "vkrt.pending.add.i32";
  return helper(g, name, ft, [&](llvm::IRBuilder<>& h, llvm::Function* f) {
    llvm::Value *adds = f->getArg(0), *addr = f->getArg(1), *v = f->getArg(2);
    auto* atomic = llvm::BasicBlock::Create(g.c, "atomic", f);
    auto* table = llvm::BasicBlock::Create(g.c, "table", f);
    auto* same = llvm::BasicBlock::Create(g.c, "same", f);
    auto* other = llvm::BasicBlock::Create(g.c, "other", f);
    auto* flush = llvm::BasicBlock::Create(g.c, "flush", f);
    auto* start = llvm::BasicBlock::Create(g.c, "start", f);
    h.CreateCondBr(h.CreateIsNull(adds), atomic, table);
    h.SetInsertPoint(atomic);
    h.CreateAtomicRMW(llvm::AtomicRMWInst::Add, addr, v, llvm::MaybeAlign(bytes),
                      llvm::AtomicOrdering::SequentiallyConsistent);
    h.CreateRetVoid();
    h.SetInsertPoint(table);
    llvm::Value* at = h.CreatePtrToInt(addr, i64);
    llvm::Value* begin = pendingField(h, adds, kPendingBegin, i64);
    llvm::Value* end = pendingField(h, adds, kPendingEnd, i64);
    llvm::Value* wide = h.CreateZExt(v, i64);
    h.CreateCondBr(h.CreateAnd(h.CreateICmpEQ(begin, at), h.CreateICmpEQ(end, h.CreateAdd(at, h.getInt64(bytes)))),
                   same, other);
    h.SetInsertPoint(same);
    setPendingField(h, adds, kPendingSum, h.CreateAdd(pendingField(h, adds, kPendingSum, i64), wide));
    h.CreateRetVoid();
    h.SetInsertPoint(other);  // another word (or none) is pending: it is written first
    h.CreateCondBr(h.CreateICmpNE(end, h.getInt64(0)), flush, start);
    h.SetInsertPoint(flush);
    callFlush(h, adds);
    h.CreateBr(start);
    h.SetInsertPoint(start);
    setPendingField(h, adds, kPendingBegin, at);
    setPendingField(h, adds, kPendingEnd, h.CreateAdd(at, h.getInt64(bytes)));
    setPendingField(h, adds, kPendingSum, wide);
    h.CreateRetVoid();
  });
}

}  // namespace

void Codegen::flushOverlappingAdds(const Ptr& p, uint64_t bytes) {
  if (!combining) return;
  switch (p.storage) {
    case spv::StorageClassStorageBuffer:
    case spv::StorageClassUniform:
    case spv::StorageClassPhysicalStorageBuffer:
    case spv::StorageClassShaderRecordBufferKHR: break;
    default: return;  // the invocation's own memory (function, private, payloads, attributes) or push constants
  }
  llvm::Value* at = b.CreatePtrToInt(b.CreateGEP(b.getInt8Ty(), p.base, p.offset), b.getInt64Ty());
  b.CreateCall(overlapHelper(*this), {ctxField(*this, offsetof(RayInvocation, pendingAdds)), at, i64(bytes)});
}

void Codegen::flushPendingAdds() {
  if (!combining) return;
  // An access that may reach any address overlaps every word: [0, 2^64 - 1) holds every begin a table can have, and
  // an empty table's end, 0, lies below it.
  b.CreateCall(overlapHelper(*this),
               {ctxField(*this, offsetof(RayInvocation, pendingAdds)), i64(0), i64(~uint64_t(0))});
}

bool Codegen::resultUnused(uint32_t id) {
  if (bodyWords.empty()) countBodyWords(m, bodyWords);  // once: a module with a function has its words
  auto it = bodyWords.find(id);
  return it != bodyWords.end() && it->second == 1;  // its definition's result word alone
}

bool Codegen::combinableAdd(const Instruction& in, const Ptr& p) {
  if (!combining) return false;
  if (!combinableAddOp(in.op)) return false;
  // Through a buffer descriptor (an address a physical pointer computes is left to fault where the shader has it).
  if (p.resource < 0 || (p.storage != spv::StorageClassStorageBuffer && p.storage != spv::StorageClassUniform))
    return false;
  const Type& t = spvType(p.type);
  if (t.kind != Type::Int || (t.width != 32 && t.width != 64)) return false;
  uint64_t semantics = 0;
  if (!m.constantU64(in.word(5), &semantics) || !relaxedSemantics(semantics)) return false;
  return resultUnused(in.word(2));
}

// The atomic instructions (Codegen::memory): sequentially consistent, on p's address or the sink out of bounds.
bool Codegen::atomic(const Instruction& in, bool& ok) {
  bool isStore = in.op == spv::OpAtomicStore;
  Ptr p;
  if (!operandPtr(*this, in, in.word(isStore ? 1 : 3), &p)) return (ok = false), true;
  const Type& t = spvType(p.type);
  if (p.slot >= 0 || t.kind != Type::Int) return (ok = unsupported(in, "atomic on a non-integer")), true;
  uint64_t bytes = t.width / 8;
  llvm::Type* ty = type(p.type);
  auto order = llvm::AtomicOrdering::SequentiallyConsistent;
  // An add whose result is unused may go to the worker's pending sum (abi::PendingAdds); any other atomic writes the
  // pending sum first (its own word, or a release that orders it).
  const bool combined = combinableAdd(in, p);
  if (!combined) flushPendingAdds();
  if (in.op == spv::OpAtomicLoad) {
    auto* l = b.CreateAlignedLoad(ty, address(p, bytes, false), llvm::Align(bytes));
    l->setAtomic(order);
    set(in.word(2), l);
    return true;
  }
  llvm::Value* addr = address(forWrite(p), bytes, true);
  if (isStore) {
    auto* s = b.CreateAlignedStore(value(in.word(4)), addr, llvm::Align(bytes));
    s->setAtomic(order);
    return true;
  }
  if (in.op == spv::OpAtomicCompareExchange) {
    auto* x = b.CreateAtomicCmpXchg(addr, value(in.word(8)), value(in.word(7)), llvm::MaybeAlign(bytes), order, order);
    set(in.word(2), b.CreateExtractValue(x, {0}));
    return true;
  }
  llvm::AtomicRMWInst::BinOp op = llvm::AtomicRMWInst::Add;
  llvm::Value* operand = nullptr;
  switch (in.op) {
    case spv::OpAtomicIIncrement: operand = llvm::ConstantInt::get(ty, 1); break;
    case spv::OpAtomicIDecrement:
      op = llvm::AtomicRMWInst::Sub;
      operand = llvm::ConstantInt::get(ty, 1);
      break;
    case spv::OpAtomicExchange: op = llvm::AtomicRMWInst::Xchg; break;
    case spv::OpAtomicISub: op = llvm::AtomicRMWInst::Sub; break;
    case spv::OpAtomicSMin: op = llvm::AtomicRMWInst::Min; break;
    case spv::OpAtomicUMin: op = llvm::AtomicRMWInst::UMin; break;
    case spv::OpAtomicSMax: op = llvm::AtomicRMWInst::Max; break;
    case spv::OpAtomicUMax: op = llvm::AtomicRMWInst::UMax; break;
    case spv::OpAtomicAnd: op = llvm::AtomicRMWInst::And; break;
    case spv::OpAtomicOr: op = llvm::AtomicRMWInst::Or; break;
    case spv::OpAtomicXor: op = llvm::AtomicRMWInst::Xor; break;
    default: break;
  }
  if (!operand) operand = value(in.word(6));
  if (!operand) return (ok = fail(in, "atomic operand has no value")), true;
  if (combined) {  // the sum of a subtraction's negations; atomic where the invocation has no table
    if (op == llvm::AtomicRMWInst::Sub) operand = b.CreateNeg(operand);
    b.CreateCall(pendingAddHelper(*this, ty), {ctxField(*this, offsetof(RayInvocation, pendingAdds)), addr, operand});
    return true;
  }
  set(in.word(2), b.CreateAtomicRMW(op, addr, operand, llvm::MaybeAlign(bytes), order));
  return true;
}

}  // namespace vkrt::spirv
