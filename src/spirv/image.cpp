// SPIR-V -> LLVM IR: images and samplers. Image, sampler and sampled-image values are {image record,
// sampler record} pairs of DescriptorRecord pointers; the operations call the runtime functions of
// abi/image_functions.hpp with their coordinates and texels in small stack buffers (four 32-bit words each).
#include <llvm/IR/Constants.h>

#include "spirv/codegen.hpp"

namespace vkrt::spirv {

bool extraSupportedCapability(uint32_t cap) {
  switch (cap) {
    // Only what tests/e2e/compute_image_test.cpp and tests/spirv/image_bda_test.cpp exercise.
    case spv::CapabilityImageQuery:
    // Cube array views (sampleCube in image.cpp, the runtime's vkrt_image_sample_cube; storage reads and writes as 2D
    // arrays); tests/e2e ComputeImageTest.CubeMapsSelectTheFaceFilterAcrossEdgesAndGather.
    case spv::CapabilitySampledCubeArray:
    case spv::CapabilityImageCubeArray:
    case spv::CapabilityPhysicalStorageBufferAddresses:
    case spv::CapabilityStorageBuffer8BitAccess:
    case spv::CapabilityStorageBuffer16BitAccess:
    // 8/16-bit members of uniform and push-constant blocks: memory.cpp loads every scalar at its own width
    // and offset whatever the storage class (tests/spirv/small_uniform_test.cpp).
    case spv::CapabilityUniformAndStorageBuffer8BitAccess:
    case spv::CapabilityUniformAndStorageBuffer16BitAccess:
    case spv::CapabilityStoragePushConstant8:
    case spv::CapabilityStoragePushConstant16:
    // Texel buffers (Dim Buffer images; Codegen::texelBuffer); tests/e2e/texel_buffer_test.cpp.
    case spv::CapabilitySampledBuffer:
    case spv::CapabilityImageBuffer:
    // Descriptor arrays of buffers, images and texel buffers indexed by any value, per invocation (every access
    // resolves its own descriptor record); tests/spirv/descriptor_indexing_test.cpp, tests/e2e/texel_buffer_test.cpp.
    // Arrays of input attachments are not offered (shaderInputAttachmentArray*Indexing), so their indexing
    // capabilities stay refused.
    case spv::CapabilityUniformTexelBufferArrayDynamicIndexing:
    case spv::CapabilityStorageTexelBufferArrayDynamicIndexing:
    case spv::CapabilityUniformTexelBufferArrayNonUniformIndexing:
    case spv::CapabilityStorageTexelBufferArrayNonUniformIndexing:
    case spv::CapabilityShaderNonUniform:
    case spv::CapabilityRuntimeDescriptorArray:
    case spv::CapabilityUniformBufferArrayDynamicIndexing:
    case spv::CapabilitySampledImageArrayDynamicIndexing:
    case spv::CapabilityStorageBufferArrayDynamicIndexing:
    case spv::CapabilityStorageImageArrayDynamicIndexing:
    case spv::CapabilityUniformBufferArrayNonUniformIndexing:
    case spv::CapabilitySampledImageArrayNonUniformIndexing:
    case spv::CapabilityStorageBufferArrayNonUniformIndexing:
    case spv::CapabilityStorageImageArrayNonUniformIndexing:
    // Workgroup blocks with explicit layouts, aliasing one another (memory.cpp's declareGlobals); 8/16-bit members
    // load and store at their own width, as in other storage classes.
    case spv::CapabilityWorkgroupMemoryExplicitLayoutKHR:
    case spv::CapabilityWorkgroupMemoryExplicitLayout8BitAccessKHR:
    case spv::CapabilityWorkgroupMemoryExplicitLayout16BitAccessKHR:
    // Storage images of Image Format Unknown (OpImageRead / OpImageWrite): nothing here depends on the declared
    // format. The image functions convert every texel from or to the format of the view bound when the shader
    // runs (runtime/image_functions.cpp), which is what the spec asks of format-less access ("Image Format
    // Unknown": the view's format decides). tests/spirv/formatless_image_test.cpp, tests/e2e
    // ComputeFormatless* and FormatlessRaygenTest.
    case spv::CapabilityStorageImageReadWithoutFormat:
    case spv::CapabilityStorageImageWriteWithoutFormat:
    // Vulkan 1.0 enables these three unconditionally (vk.xml's spirvcapability table). The declared format of a
    // storage image changes nothing here (above), so the extended formats are as any other; 1D images and
    // samplers take one coordinate (and a layer) through the same image functions, which read the view's type
    // (runtime/image_functions.cpp). tests/e2e ComputeImageTest.OneDimensionalImagesAndExtendedStorageFormats.
    case spv::CapabilityStorageImageExtendedFormats:
    case spv::CapabilityImage1D:
    case spv::CapabilitySampled1D:
    // Input attachments: images of Dim SubpassData read at the fragment's own position (Codegen::subpassRead;
    // tests/e2e InputAttachmentTest).
    case spv::CapabilityInputAttachment: return true;
    default: return false;
  }
}

bool Codegen::isImageLike(uint32_t typeId) const {
  const Instruction* d = m.def(typeId);
  return d && (d->op == spv::OpTypeImage || d->op == spv::OpTypeSampler || d->op == spv::OpTypeSampledImage);
}

bool Codegen::isTexelBuffer(uint32_t typeId) const {
  const Instruction* d = m.def(typeId);
  return d && d->op == spv::OpTypeImage && d->word(3) == spv::DimBuffer;
}

llvm::Type* Codegen::imageValueType() { return llvm::StructType::get(c, {b.getPtrTy(), b.getPtrTy()}); }

namespace {

// The OpTypeImage behind an image or sampled-image value's type (nullptr for anything else).
const Instruction* imageTypeOf(const Module& m, uint32_t valueId) {
  const Instruction* t = m.def(m.typeOf(valueId));
  if (t && t->op == spv::OpTypeSampledImage) t = m.def(t->word(2));
  return t && t->op == spv::OpTypeImage ? t : nullptr;
}

// A 16-byte stack buffer in the function's entry block.
llvm::Value* scratch(Codegen& g) {
  llvm::IRBuilderBase::InsertPointGuard guard(g.b);
  g.b.SetInsertPoint(g.allocaBlock->getTerminator());
  auto* a = g.b.CreateAlloca(llvm::ArrayType::get(g.b.getInt32Ty(), 4));
  a->setAlignment(llvm::Align(16));
  return a;
}

// Stores the (scalar or vector) value `v` as four 32-bit words: floats as float, integers as i32; missing
// components are zero.
llvm::Value* toWords(Codegen& g, llvm::Value* v, bool isFloatValue) {
  llvm::Value* buf = scratch(g);
  auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(v->getType());
  unsigned n = vt ? std::min(4u, unsigned(vt->getNumElements())) : 1;
  // The four words (those past the value's components 0) in one 16-byte store: the runtime function may read them
  // in one wide load, which a store of each word (after a store of zeros) could not forward to (it would wait for
  // the stores to reach the cache: every imageStore paid it).
  llvm::Value* words = llvm::Constant::getNullValue(llvm::FixedVectorType::get(g.b.getInt32Ty(), 4));
  for (unsigned i = 0; i < n; ++i) {
    llvm::Value* e = vt ? g.b.CreateExtractElement(v, uint64_t(i)) : v;
    if (isFloatValue)
      e = g.b.CreateBitCast(g.b.CreateFPCast(e, g.b.getFloatTy()), g.b.getInt32Ty());
    else
      e = g.b.CreateSExtOrTrunc(e, g.b.getInt32Ty());
    words = g.b.CreateInsertElement(words, e, uint64_t(i));
  }
  g.b.CreateAlignedStore(words, buf, llvm::Align(16));
  return buf;
}

// Reads four words back as a value of SPIR-V type `typeId` (scalar or vector of up to 4 components).
llvm::Value* fromWords(Codegen& g, llvm::Value* buf, uint32_t typeId) {
  llvm::Type* rt = g.type(typeId);
  uint32_t st = g.scalarType(typeId);
  llvm::Type* et = g.type(st);
  bool fl = g.isFloat(typeId);
  unsigned n = g.componentCount(typeId);
  llvm::Value* r = n > 1 ? static_cast<llvm::Value*>(llvm::UndefValue::get(rt)) : nullptr;
  for (unsigned i = 0; i < n; ++i) {
    llvm::Value* w = g.b.CreateLoad(g.b.getInt32Ty(), g.b.CreateConstGEP1_64(g.b.getInt32Ty(), buf, i));
    llvm::Value* e = fl ? g.b.CreateFPCast(g.b.CreateBitCast(w, g.b.getFloatTy()), et)
                        : (g.isSignedInt(typeId) ? g.b.CreateSExtOrTrunc(w, et) : g.b.CreateZExtOrTrunc(w, et));
    r = n > 1 ? g.b.CreateInsertElement(r, e, uint64_t(i)) : e;
  }
  return r;
}

llvm::FunctionCallee runtimeFn(Codegen& g, const char* name, llvm::Type* ret, std::vector<llvm::Type*> params) {
  return g.out.getOrInsertFunction(name, llvm::FunctionType::get(ret, params, false));
}

// A texel buffer's coordinate (a scalar integer of any width and signedness) as the i64 index the texel buffer
// functions take: a negative signed index stays negative, out of range as a large unsigned one is.
llvm::Value* texelIndex(Codegen& g, llvm::Value* coord, uint32_t coordType) {
  if (llvm::isa<llvm::FixedVectorType>(coord->getType())) coord = g.b.CreateExtractElement(coord, uint64_t(0));
  return g.isSignedInt(coordType) ? g.b.CreateSExtOrTrunc(coord, g.b.getInt64Ty())
                                  : g.b.CreateZExtOrTrunc(coord, g.b.getInt64Ty());
}

// What kind of sampling instruction `op` is.
struct SampleKind {
  bool implicit = false, explicitLod = false, dref = false, proj = false, gather = false;
};

SampleKind sampleKind(spv::Op op) {
  SampleKind k;
  switch (op) {
    case spv::OpImageSampleImplicitLod: k.implicit = true; break;
    case spv::OpImageSampleExplicitLod: k.explicitLod = true; break;
    case spv::OpImageSampleDrefImplicitLod: k.implicit = k.dref = true; break;
    case spv::OpImageSampleDrefExplicitLod: k.explicitLod = k.dref = true; break;
    case spv::OpImageSampleProjImplicitLod: k.implicit = k.proj = true; break;
    case spv::OpImageSampleProjExplicitLod: k.explicitLod = k.proj = true; break;
    case spv::OpImageSampleProjDrefImplicitLod: k.implicit = k.proj = k.dref = true; break;
    case spv::OpImageSampleProjDrefExplicitLod: k.explicitLod = k.proj = k.dref = true; break;
    case spv::OpImageGather: k.gather = true; break;
    case spv::OpImageDrefGather: k.gather = k.dref = true; break;
    default: break;
  }
  return k;
}

// Sampling and gathering from a cube or cube array view (the runtime's vkrt_image_sample_cube and
// vkrt_image_gather_cube select the face, "Cube Map Face Selection"): the direction (and the cube array layer),
// its derivatives for the implicit-LOD forms in fragment shaders or the Grad operand, else the Lod (or Bias outside
// fragment shaders). SPIR-V allows neither Proj nor an offset with Dim Cube.
bool sampleCube(Codegen& g, const Instruction& in, const SampleKind& kind, llvm::Value* img, llvm::Value* coord,
                uint32_t coordId, llvm::Value* lod, llvm::Value* bias, llvm::Value* gradX, llvm::Value* gradY,
                llvm::Value* offset) {
  llvm::Type* ptrTy = g.b.getPtrTy();
  llvm::Type* f32 = g.b.getFloatTy();
  llvm::Type* i32 = g.b.getInt32Ty();
  if (!g.isFloat(g.m.typeOf(coordId))) return g.fail(in, "sampling coordinates are not floats");
  const unsigned n = g.componentCount(g.m.typeOf(coordId));
  if (kind.proj || offset || n < 3)
    return g.fail(in, "cube map sampling with Proj, an offset or fewer than 3 coordinates");
  if (kind.explicitLod && !lod && !gradX) return g.fail(in, "explicit-LOD sampling without Lod or Grad");
  llvm::Value* imgRec = g.b.CreateExtractValue(img, {0});
  llvm::Value* smpRec = g.b.CreateExtractValue(img, {1});
  llvm::Value* c = g.b.CreateFPCast(coord, llvm::FixedVectorType::get(f32, n));
  llvm::Value* coords = toWords(g, c, true);
  llvm::Value* dref = llvm::ConstantFP::get(f32, 0.0);
  uint32_t flags = 0;  // abi::kCube*
  if (kind.dref) {
    llvm::Value* d = g.value(in.word(5));
    if (!d) return g.fail(in, "Dref has no value");
    dref = g.b.CreateFPCast(d, f32);
    flags |= abi::kCubeDref;
  }
  llvm::Value* out = scratch(g);
  if (kind.gather) {
    llvm::Value* component = g.b.getInt32(0);
    if (!kind.dref) {
      llvm::Value* v = g.value(in.word(5));
      if (!v) return g.fail(in, "Component has no value");
      component = g.b.CreateSExtOrTrunc(v, i32);
    }
    g.b.CreateCall(runtimeFn(g, "vkrt_image_gather_cube", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, i32, f32, i32, ptrTy}),
                   {imgRec, smpRec, coords, component, dref, g.b.getInt32(flags), out});
    g.set(in.word(2), fromWords(g, out, in.word(1)));
    return true;
  }
  const bool implicitHere = kind.implicit && g.isFragment();
  llvm::Value* ddx = llvm::ConstantPointerNull::get(g.b.getPtrTy());
  llvm::Value* ddy = ddx;
  llvm::Value* level;
  if (gradX || implicitHere) {
    llvm::Value *dx = gradX, *dy = gradY;
    if (implicitHere) {
      // The direction's derivatives (not the array layer's).
      llvm::Value* dir = g.b.CreateShuffleVector(c, {0, 1, 2});
      g.derivatives(dir, true, &dx, &dy);
    }
    if (!dx || !dy) return g.fail(in, "Grad operands have no value");
    ddx = toWords(g, dx, true);
    ddy = toWords(g, dy, true);
    flags |= abi::kCubeGrad;
    level = bias ? g.b.CreateFPCast(bias, f32) : llvm::ConstantFP::getNaN(f32);
  } else {
    level = g.b.CreateFPCast(lod ? lod : bias ? bias : llvm::ConstantFP::get(f32, 0.0), f32);
  }
  g.b.CreateCall(runtimeFn(g, "vkrt_image_sample_cube", g.b.getVoidTy(),
                           {ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, f32, f32, i32, ptrTy}),
                 {imgRec, smpRec, coords, ddx, ddy, level, dref, g.b.getInt32(flags), out});
  g.set(in.word(2), fromWords(g, out, in.word(1)));
  return true;
}

// The sampling instructions (OpImageSample*, OpImage*Gather) on image `img` ({image record, sampler record}) with
// their coordinate and the image operands image() has read. The Proj forms divide the coordinates (and Dref) by
// their last component ("Projection Operation"); the implicit-LOD forms take the coordinates' quad derivatives in
// fragment shaders and level 0 elsewhere (plus the Bias operand); the explicit ones take Lod or Grad.
bool sample(Codegen& g, const Instruction& in, const SampleKind& kind, const Instruction& imageType, llvm::Value* img,
            llvm::Value* coord, uint32_t coordId, llvm::Value* lod, llvm::Value* bias, llvm::Value* gradX,
            llvm::Value* gradY, llvm::Value* offset) {
  llvm::Type* ptrTy = g.b.getPtrTy();
  if (imageType.word(3) == spv::DimCube)
    return sampleCube(g, in, kind, img, coord, coordId, lod, bias, gradX, gradY, offset);
  if (!g.isFloat(g.m.typeOf(coordId))) return g.fail(in, "sampling coordinates are not floats");
  if (kind.explicitLod && !lod && !gradX) return g.fail(in, "explicit-LOD sampling without Lod or Grad");
  llvm::Value* imgRec = g.b.CreateExtractValue(img, {0});
  llvm::Value* smpRec = g.b.CreateExtractValue(img, {1});
  llvm::Type* f32 = g.b.getFloatTy();
  // The coordinates as f32 (a scalar or a vector of their component count).
  unsigned n = g.componentCount(g.m.typeOf(coordId));
  llvm::Value* c = g.b.CreateFPCast(coord, n > 1 ? static_cast<llvm::Type*>(llvm::FixedVectorType::get(f32, n)) : f32);
  llvm::Value* dref = nullptr;
  if (kind.dref) {
    dref = g.value(in.word(5));
    if (!dref) return g.fail(in, "Dref has no value");
    dref = g.b.CreateFPCast(dref, f32);
  }
  if (kind.proj) {
    // (u [, v] [, w], q): q follows the Dim's coordinates; Proj takes no arrayed image.
    const uint32_t dim = imageType.word(3);
    const unsigned dims = dim == spv::Dim1D ? 1 : dim == spv::Dim3D ? 3 : 2;
    if (imageType.word(5) != 0 || n <= dims) return g.fail(in, "projective sampling of an arrayed image or without q");
    llvm::Value* q = g.b.CreateExtractElement(c, uint64_t(dims));
    llvm::Value* p =
        dims > 1 ? static_cast<llvm::Value*>(llvm::UndefValue::get(llvm::FixedVectorType::get(f32, dims))) : nullptr;
    for (unsigned i = 0; i < dims; ++i) {
      llvm::Value* e = g.b.CreateFDiv(g.b.CreateExtractElement(c, uint64_t(i)), q);
      p = dims > 1 ? g.b.CreateInsertElement(p, e, uint64_t(i)) : e;
    }
    c = p;
    if (dref) dref = g.b.CreateFDiv(dref, q);
  }
  llvm::Value* coords = toWords(g, c, true);
  llvm::Value* out = scratch(g);
  if (kind.gather) {
    if (imageType.word(3) != spv::Dim2D) return g.fail(in, "gather from an image that is not 2D");
    if (dref) {
      g.b.CreateCall(runtimeFn(g, "vkrt_image_gather_dref", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, f32, ptrTy}),
                     {imgRec, smpRec, coords, dref, out});
    } else {
      llvm::Value* component = g.value(in.word(5));
      if (!component) return g.fail(in, "Component has no value");
      g.b.CreateCall(runtimeFn(g, "vkrt_image_gather", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, g.b.getInt32Ty(), ptrTy}),
                     {imgRec, smpRec, coords, g.b.CreateSExtOrTrunc(component, g.b.getInt32Ty()), out});
    }
    g.set(in.word(2), fromWords(g, out, in.word(1)));
    return true;
  }
  // ConstOffset: its integers as four words, or a null pointer (the Dref functions take either).
  llvm::Value* offsetWords = offset ? toWords(g, offset, false) : llvm::ConstantPointerNull::get(g.b.getPtrTy());
  const bool implicitHere = kind.implicit && g.isFragment();
  if (gradX || implicitHere) {
    // With gradients: the Grad operand's, or the coordinates' quad derivatives in fragment shaders.
    llvm::Value *dx = gradX, *dy = gradY;
    if (implicitHere) g.derivatives(c, true, &dx, &dy);
    llvm::Value* biasValue = bias ? g.b.CreateFPCast(bias, f32) : llvm::ConstantFP::getNaN(f32);
    llvm::Value* ddx = toWords(g, dx, true);
    llvm::Value* ddy = toWords(g, dy, true);
    if (dref)
      g.b.CreateCall(runtimeFn(g, "vkrt_image_sample_grad_dref", g.b.getVoidTy(),
                               {ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, f32, f32, ptrTy, ptrTy}),
                     {imgRec, smpRec, coords, ddx, ddy, biasValue, dref, offsetWords, out});
    else if (offset)
      g.b.CreateCall(runtimeFn(g, "vkrt_image_sample_grad_offset", g.b.getVoidTy(),
                               {ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, f32, ptrTy, ptrTy}),
                     {imgRec, smpRec, coords, ddx, ddy, biasValue, offsetWords, out});
    else
      g.b.CreateCall(
          runtimeFn(g, "vkrt_image_sample_grad", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, ptrTy, ptrTy, f32, ptrTy}),
          {imgRec, smpRec, coords, ddx, ddy, biasValue, out});
  } else {
    // An explicit Lod; implicit LOD outside fragment shaders is level 0 (plus the Bias operand).
    llvm::Value* level = g.b.CreateFPCast(lod ? lod : bias ? bias : llvm::ConstantFP::get(f32, 0.0), f32);
    if (dref)
      g.b.CreateCall(
          runtimeFn(g, "vkrt_image_sample_dref", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, f32, f32, ptrTy, ptrTy}),
          {imgRec, smpRec, coords, level, dref, offsetWords, out});
    else if (offset)
      g.b.CreateCall(
          runtimeFn(g, "vkrt_image_sample_offset", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, f32, ptrTy, ptrTy}),
          {imgRec, smpRec, coords, level, offsetWords, out});
    else
      g.b.CreateCall(runtimeFn(g, "vkrt_image_sample", g.b.getVoidTy(), {ptrTy, ptrTy, ptrTy, f32, ptrTy}),
                     {imgRec, smpRec, coords, level, out});
  }
  g.set(in.word(2), fromWords(g, out, in.word(1)));
  return true;
}

}  // namespace

bool Codegen::image(const Instruction& in, bool& ok) {
  llvm::Type* ptrTy = b.getPtrTy();
  switch (in.op) {
    case spv::OpSampledImage:
    case spv::OpImage: {
      llvm::Value* img = value(in.word(3));
      llvm::Value* smp = in.op == spv::OpSampledImage ? value(in.word(4)) : img;
      if (!img || !smp) return (ok = fail(in, "image or sampler operand has no value")), true;
      llvm::Value* v = llvm::UndefValue::get(imageValueType());
      v = b.CreateInsertValue(v, b.CreateExtractValue(img, {0}), {0});
      set(in.word(2), b.CreateInsertValue(v, b.CreateExtractValue(smp, {in.op == spv::OpSampledImage ? 1u : 0u}), {1}));
      return true;
    }
    case spv::OpImageTexelPointer: {
      // A pointer (Image storage class) to a storage image texel, for the atomic instructions: the texel's address
      // from the image functions, or the zero sink (limit 0) where there is none, so that atomics land nowhere.
      Ptr& image = ptr(in.word(3));
      llvm::Value* coord = value(in.word(4));
      if (image.slot < 0 || !coord) return (ok = fail(in, "image pointer or coordinate has no value")), true;
      // Atomics through the pointer write: none in helper lanes of fragment shaders (writableRecord).
      llvm::Value* rec = writableRecord(descriptorRecord(image.slot, image.descIndex ? image.descIndex : i64(0)));
      llvm::Value* texel = nullptr;
      if (isTexelBuffer(image.type)) {
        llvm::Value* index = texelIndex(*this, coord, m.typeOf(in.word(4)));
        checkTexelBuffer(in.word(3), true, abi::kAccessTexelAtomic, rec, index);  // VKRT_SHADER_CHECKS=image
        texel = b.CreateCall(runtimeFn(*this, "vkrt_texel_buffer_texel", ptrTy, {ptrTy, b.getInt64Ty()}), {rec, index});
      } else {
        llvm::Value* words = toWords(*this, coord, false);
        checkImage(in.word(3), true, abi::kAccessImageAtomic, rec, words, nullptr);
        texel = b.CreateCall(runtimeFn(*this, "vkrt_image_texel", ptrTy, {ptrTy, ptrTy}), {rec, words});
      }
      llvm::Value* none = b.CreateIsNull(texel);
      Ptr p;
      p.base = b.CreateSelect(none, zeros, texel);
      p.offset = i64(0);
      p.limit = b.CreateSelect(none, i64(0), i64(4));
      p.type = spvType(in.word(1)).element;
      p.storage = spv::StorageClassImage;
      ptrs[in.word(2)] = p;
      return true;
    }
    case spv::OpImageRead:
    case spv::OpImageWrite:
    case spv::OpImageFetch:
    case spv::OpImageSampleExplicitLod:
    case spv::OpImageSampleImplicitLod:
    case spv::OpImageSampleDrefImplicitLod:
    case spv::OpImageSampleDrefExplicitLod:
    case spv::OpImageSampleProjImplicitLod:
    case spv::OpImageSampleProjExplicitLod:
    case spv::OpImageSampleProjDrefImplicitLod:
    case spv::OpImageSampleProjDrefExplicitLod:
    case spv::OpImageGather:
    case spv::OpImageDrefGather:
    case spv::OpImageQuerySize:
    case spv::OpImageQuerySizeLod:
    case spv::OpImageQueryLevels: break;
    default: return false;
  }
  bool write = in.op == spv::OpImageWrite;
  uint32_t imageId = in.word(write ? 1 : 3);
  const Instruction* it = imageTypeOf(m, imageId);
  llvm::Value* img = value(imageId);
  if (!it || !img) return (ok = fail(in, "image operand has no value")), true;
  llvm::Value* imgRec = b.CreateExtractValue(img, {0});
  if (it->word(3) == spv::DimBuffer) return (ok = texelBuffer(in, imgRec)), true;
  if (it->word(3) == spv::DimSubpassData) return (ok = subpassRead(in, *it, imgRec)), true;
  // Multisampled sampled and storage images are not supported yet.
  if (it->word(6) != 0) return (ok = unsupported(in, "multisampled image")), true;
  switch (in.op) {
    case spv::OpImageQuerySize:
    case spv::OpImageQuerySizeLod: {
      llvm::Value* lod = i32(0);
      if (in.op == spv::OpImageQuerySizeLod) {
        lod = value(in.word(4));
        if (!lod) return (ok = fail(in, "level of detail has no value")), true;
        lod = b.CreateSExtOrTrunc(lod, b.getInt32Ty());
      }
      llvm::Value* out = scratch(*this);
      b.CreateCall(runtimeFn(*this, "vkrt_image_size", b.getVoidTy(), {ptrTy, b.getInt32Ty(), ptrTy}),
                   {imgRec, lod, out});
      set(in.word(2), fromWords(*this, out, in.word(1)));
      return true;
    }
    case spv::OpImageQueryLevels: {
      llvm::Value* n = b.CreateCall(runtimeFn(*this, "vkrt_image_levels", b.getInt32Ty(), {ptrTy}), {imgRec});
      set(in.word(2), b.CreateZExtOrTrunc(n, type(in.word(1))));
      return true;
    }
    default: break;
  }
  // Coordinates and image operands.
  uint32_t coordId = in.word(write ? 2 : 4);
  llvm::Value* coord = value(coordId);
  if (!coord) return (ok = fail(in, "coordinate has no value")), true;
  const SampleKind kind = sampleKind(in.op);
  // The Dref and Gather forms have one operand (Dref, Component) before the image operands.
  uint32_t operandsAt = write ? 4 : (kind.dref || kind.gather) ? 6 : 5;
  uint32_t mask = in.count > operandsAt ? in.word(operandsAt) : 0;
  llvm::Value *lod = nullptr, *bias = nullptr, *gradX = nullptr, *gradY = nullptr, *offset = nullptr;
  const uint32_t biasBit = spv::ImageOperandsBiasMask, lodBit = spv::ImageOperandsLodMask,
                 gradBit = spv::ImageOperandsGradMask, offsetBit = spv::ImageOperandsConstOffsetMask;
  const uint32_t ignorable = spv::ImageOperandsSignExtendMask | spv::ImageOperandsZeroExtendMask |
                             spv::ImageOperandsNontemporalMask | spv::ImageOperandsNonPrivateTexelMask |
                             spv::ImageOperandsMakeTexelAvailableMask | spv::ImageOperandsMakeTexelVisibleMask;
  uint32_t allowed = lodBit | ignorable;
  if (kind.implicit) allowed = biasBit | ignorable;
  if (kind.explicitLod) allowed |= gradBit;
  // ConstOffset on the sampling instructions; on gathers it needs ImageGatherExtended, which is not offered.
  if (kind.implicit || kind.explicitLod) allowed |= offsetBit;
  if (kind.gather) allowed = ignorable;
  if (mask & ~allowed) return (ok = unsupported(in, "image operands other than Lod, Bias, Grad and ConstOffset")), true;
  // The operands follow the mask in the order of their bits (Bias, Lod, Grad's two, ConstOffset).
  uint32_t at = operandsAt + 1;
  auto operand = [&](llvm::Value** v) {
    *v = value(in.word(at++));
    return *v != nullptr;
  };
  if ((mask & biasBit) && !operand(&bias)) return (ok = fail(in, "Bias operand has no value")), true;
  if ((mask & lodBit) && !operand(&lod)) return (ok = fail(in, "Lod operand has no value")), true;
  if ((mask & gradBit) && (!operand(&gradX) || !operand(&gradY)))
    return (ok = fail(in, "Grad operands have no value")), true;
  if ((mask & offsetBit) && !operand(&offset)) return (ok = fail(in, "ConstOffset operand has no value")), true;
  if (kind.implicit || kind.explicitLod || kind.gather)
    return (ok = sample(*this, in, kind, *it, img, coord, coordId, lod, bias, gradX, gradY, offset)), true;
  if (write) imgRec = writableRecord(imgRec);  // helper lanes of fragment shaders write nothing
  llvm::Value* coords = toWords(*this, coord, isFloat(m.typeOf(coordId)));
  // VKRT_SHADER_CHECKS=image: the coordinates (and the level of a fetch) checked against the view, reported there.
  const uint32_t checkKind = in.op == spv::OpImageRead    ? abi::kAccessImageRead
                             : in.op == spv::OpImageWrite ? abi::kAccessImageWrite
                                                          : abi::kAccessImageFetch;
  checkImage(imageId, false, checkKind, imgRec, coords,
             in.op == spv::OpImageFetch && lod ? b.CreateSExtOrTrunc(lod, b.getInt32Ty()) : nullptr);
  switch (in.op) {
    case spv::OpImageRead: {
      llvm::Value* out = scratch(*this);
      b.CreateCall(runtimeFn(*this, "vkrt_image_read", b.getVoidTy(), {ptrTy, ptrTy, ptrTy}), {imgRec, coords, out});
      set(in.word(2), fromWords(*this, out, in.word(1)));
      return true;
    }
    case spv::OpImageWrite: {
      llvm::Value* texel = value(in.word(3));
      if (!texel) return (ok = fail(in, "texel has no value")), true;
      llvm::Value* words = toWords(*this, texel, isFloat(m.typeOf(in.word(3))));
      b.CreateCall(runtimeFn(*this, "vkrt_image_write", b.getVoidTy(), {ptrTy, ptrTy, ptrTy}), {imgRec, coords, words});
      return true;
    }
    case spv::OpImageFetch: {
      llvm::Value* level = lod ? b.CreateSExtOrTrunc(lod, b.getInt32Ty()) : i32(0);
      llvm::Value* out = scratch(*this);
      b.CreateCall(runtimeFn(*this, "vkrt_image_fetch", b.getVoidTy(), {ptrTy, ptrTy, b.getInt32Ty(), ptrTy}),
                   {imgRec, coords, level, out});
      set(in.word(2), fromWords(*this, out, in.word(1)));
      return true;
    }
    default: return false;
  }
}

// OpImageRead on an image of Dim SubpassData (an input attachment, "Input Attachment Operations" in the spec's
// fragment chapter): the texel at the fragment's own framebuffer position, (int) FragCoord.xy plus the coordinate
// operand (a constant offset, which the Vulkan environment requires to be zero but SPIR-V defines as an offset), in
// the layer of the fragment (with multiview: the view index's; GraphicsInvocation::layer holds either); the Sample
// operand picks the sample of a multisampled attachment (subpassInputMS).
bool Codegen::subpassRead(const Instruction& in, const Instruction& imageType, llvm::Value* record) {
  if (in.op != spv::OpImageRead) return unsupported(in, "subpass data other than OpImageRead");
  if (!isFragment()) return fail(in, "subpass data outside a fragment shader");
  llvm::Type* ptrTy = b.getPtrTy();
  llvm::Value* coord = value(in.word(4));
  if (!coord) return fail(in, "coordinate has no value");
  const uint32_t mask = in.count > 5 ? in.word(5) : 0;
  const uint32_t ignorable = spv::ImageOperandsSignExtendMask | spv::ImageOperandsZeroExtendMask |
                             spv::ImageOperandsNontemporalMask | spv::ImageOperandsNonPrivateTexelMask |
                             spv::ImageOperandsMakeTexelAvailableMask | spv::ImageOperandsMakeTexelVisibleMask;
  if (mask & ~(ignorable | spv::ImageOperandsSampleMask)) return unsupported(in, "subpass data image operands");
  llvm::Value* sample = i32(0);
  if (mask & spv::ImageOperandsSampleMask) {
    // Sample is the only operand before the memory-model ones, which take ids after it.
    llvm::Value* s = in.count > 6 ? value(in.word(6)) : nullptr;
    if (!s) return fail(in, "Sample operand has no value");
    sample = b.CreateSExtOrTrunc(s, b.getInt32Ty());
  } else if (imageType.word(6) != 0) {
    return fail(in, "multisampled subpass data read without a Sample operand");
  }
  auto* vt = llvm::dyn_cast<llvm::FixedVectorType>(coord->getType());
  if (!vt || vt->getNumElements() < 2 || !vt->getElementType()->isIntegerTy())
    return fail(in, "subpass data coordinate is not an integer 2-vector");
  llvm::Value* fragCoord = b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(abi::GraphicsInvocation, fragCoord));
  llvm::Value* xy[2];
  for (unsigned k = 0; k < 2; ++k) {
    llvm::Value* f =
        b.CreateAlignedLoad(b.getFloatTy(), b.CreateConstGEP1_64(b.getFloatTy(), fragCoord, k), llvm::Align(4));
    llvm::Value* off = b.CreateSExtOrTrunc(b.CreateExtractElement(coord, uint64_t(k)), b.getInt32Ty());
    xy[k] = b.CreateAdd(b.CreateFPToSI(f, b.getInt32Ty()), off);
  }
  llvm::Value* layer = b.CreateAlignedLoad(
      b.getInt32Ty(), b.CreateConstGEP1_64(b.getInt8Ty(), ctxArg, offsetof(abi::GraphicsInvocation, layer)),
      llvm::Align(4));
  llvm::Value* out = scratch(*this);
  b.CreateCall(runtimeFn(*this, "vkrt_image_read_subpass", b.getVoidTy(),
                         {ptrTy, b.getInt32Ty(), b.getInt32Ty(), b.getInt32Ty(), b.getInt32Ty(), ptrTy}),
               {record, xy[0], xy[1], layer, sample, out});
  set(in.word(2), fromWords(*this, out, in.word(1)));
  return true;
}

// OpImageFetch / OpImageRead / OpImageWrite / OpImageQuerySize on a texel buffer (Dim Buffer: a uniform texel
// buffer when Sampled is 1, a storage texel buffer when 2): one scalar texel index, no level, no sampler; the texel
// buffer functions of abi/image_functions.hpp on the buffer view's record.
bool Codegen::texelBuffer(const Instruction& in, llvm::Value* rec) {
  llvm::Type* ptrTy = b.getPtrTy();
  if (in.op == spv::OpImageQuerySize) {
    llvm::Value* n = b.CreateCall(runtimeFn(*this, "vkrt_texel_buffer_size", b.getInt32Ty(), {ptrTy}), {rec});
    set(in.word(2), b.CreateZExtOrTrunc(n, type(in.word(1))));
    return true;
  }
  if (in.op != spv::OpImageFetch && in.op != spv::OpImageRead && in.op != spv::OpImageWrite)
    return unsupported(in, "instruction on a texel buffer");
  bool write = in.op == spv::OpImageWrite;
  uint32_t coordId = in.word(write ? 2 : 4);
  llvm::Value* coord = value(coordId);
  if (!coord) return fail(in, "coordinate has no value");
  uint32_t operandsAt = write ? 4 : 5;
  uint32_t mask = in.count > operandsAt ? in.word(operandsAt) : 0;
  // Texel buffers take no Lod, offsets or samples; the extension and memory-model operands change nothing here.
  const uint32_t ignorable = spv::ImageOperandsSignExtendMask | spv::ImageOperandsZeroExtendMask |
                             spv::ImageOperandsNontemporalMask | spv::ImageOperandsNonPrivateTexelMask |
                             spv::ImageOperandsMakeTexelAvailableMask | spv::ImageOperandsMakeTexelVisibleMask;
  if (mask & ~ignorable) return unsupported(in, "image operands on a texel buffer");
  llvm::Value* index = texelIndex(*this, coord, m.typeOf(coordId));
  // VKRT_SHADER_CHECKS=image: the index checked against the view, reported there.
  checkTexelBuffer(in.word(write ? 1 : 3), false,
                   write                        ? abi::kAccessTexelWrite
                   : in.op == spv::OpImageFetch ? abi::kAccessTexelFetch
                                                : abi::kAccessTexelRead,
                   write ? writableRecord(rec) : rec, index);
  if (write) {
    llvm::Value* texel = value(in.word(3));
    if (!texel) return fail(in, "texel has no value");
    llvm::Value* words = toWords(*this, texel, isFloat(m.typeOf(in.word(3))));
    b.CreateCall(runtimeFn(*this, "vkrt_texel_buffer_write", b.getVoidTy(), {ptrTy, b.getInt64Ty(), ptrTy}),
                 {writableRecord(rec), index, words});
    return true;
  }
  llvm::Value* out = scratch(*this);
  b.CreateCall(runtimeFn(*this, "vkrt_texel_buffer_read", b.getVoidTy(), {ptrTy, b.getInt64Ty(), ptrTy}),
               {rec, index, out});
  set(in.word(2), fromWords(*this, out, in.word(1)));
  return true;
}

}  // namespace vkrt::spirv
