// The SPIR-V reader: entry points, execution modes, decorations, types, constants, specialization, and
// malformed input.
#include <gtest/gtest.h>

#include <cstring>
#include <tuple>
#include <vector>

#include "compute_push_spec.comp.spv.h"
#include "compute_shared.comp.spv.h"
#include "spirv/module.hpp"

namespace vkrt::spirv {
namespace {

template <size_t N>
size_t wordCount(const uint32_t (&)[N]) {
  return N;
}

TEST(SpirvModule, EntryPointLocalSizeDecorationsAndTypes) {
  Module m;
  std::string error;
  ASSERT_TRUE(m.parse(kSpv_compute_shared_comp, wordCount(kSpv_compute_shared_comp), &error)) << error;
  const EntryPoint* ep = m.findEntryPoint("main", spv::ExecutionModelGLCompute);
  ASSERT_NE(ep, nullptr);
  EXPECT_EQ(ep->localSize[0], 64u);
  EXPECT_EQ(ep->localSize[1], 1u);
  EXPECT_EQ(m.findEntryPoint("main", spv::ExecutionModelFragment), nullptr);
  // Two storage buffers at set 0, bindings 0 and 1; two Workgroup arrays of 64 uints and a uint.
  int buffers = 0, shared = 0, sharedScalars = 0;
  for (const Instruction& in : m.instructions) {
    if (in.op != spv::OpVariable) continue;
    const Type* pt = m.type(in.word(1));
    ASSERT_NE(pt, nullptr);
    ASSERT_EQ(pt->kind, Type::Pointer);
    if (pt->storage == spv::StorageClassStorageBuffer) {
      EXPECT_EQ(m.decor(in.word(2)).set, 0);
      EXPECT_EQ(m.decor(in.word(2)).binding, buffers);
      const Type* block = m.type(pt->element);
      ASSERT_NE(block, nullptr);
      EXPECT_EQ(block->kind, Type::Struct);
      EXPECT_TRUE(m.decor(pt->element).block);
      EXPECT_EQ(m.memberDecor(pt->element, 0).offset, 0);
      const Type* arr = m.type(block->members[0]);
      ASSERT_NE(arr, nullptr);
      EXPECT_EQ(arr->kind, Type::RuntimeArray);
      EXPECT_EQ(m.decor(block->members[0]).arrayStride, 4);
      ++buffers;
    } else if (pt->storage == spv::StorageClassWorkgroup) {
      const Type* t = m.type(pt->element);
      ASSERT_NE(t, nullptr);
      if (t->kind == Type::Array) {
        EXPECT_EQ(t->count, 64u);
        const Type* e = m.type(t->element);
        EXPECT_TRUE(e && e->kind == Type::Int && e->width == 32 && !e->isSigned);
        ++shared;
      } else {
        EXPECT_TRUE(t->kind == Type::Int && t->width == 32);
        ++sharedScalars;
      }
    }
  }
  EXPECT_EQ(buffers, 2);
  EXPECT_EQ(shared, 2);
  EXPECT_EQ(sharedScalars, 1);
}

TEST(SpirvModule, SpecializationRewritesDefaults) {
  std::vector<uint32_t> words(kSpv_compute_push_spec_comp,
                              kSpv_compute_push_spec_comp + wordCount(kSpv_compute_push_spec_comp));
  auto value = [](uint32_t id, auto v) {
    SpecValue s{id, std::vector<uint8_t>(sizeof v)};
    std::memcpy(s.bytes.data(), &v, sizeof v);
    return s;
  };
  std::string error;
  ASSERT_TRUE(applySpecialization(words, {value(1, int32_t(-7)), value(2, uint32_t(1)), value(3, 2.5f)}, &error))
      << error;
  Module m;
  ASSERT_TRUE(m.parse(words.data(), words.size(), &error)) << error;
  int seen = 0;
  for (const auto& [id, d] : m.decorations) {
    if (d.specId < 0) continue;
    const Constant* c = m.constant(id);
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(c->spec);
    switch (d.specId) {
      case 1:
        EXPECT_EQ(int32_t(c->words[0]), -7);
        ++seen;
        break;
      case 2:
        EXPECT_EQ(c->words[0], 1u);
        ++seen;
        break;
      case 3: {
        float f;
        std::memcpy(&f, &c->words[0], 4);
        EXPECT_EQ(f, 2.5f);
        ++seen;
        break;
      }
      default: break;
    }
  }
  EXPECT_EQ(seen, 3);
  // A map entry whose size does not match its constant is an error naming the constant.
  EXPECT_FALSE(applySpecialization(words, {SpecValue{1, {1, 2}}}, &error));
  EXPECT_NE(error.find("specialization constant 1"), std::string::npos) << error;
}

TEST(SpirvModule, MalformedInputIsAnErrorNotACrash) {
  std::string error;
  Module a;
  EXPECT_FALSE(a.parse(kSpv_compute_shared_comp, 3, &error));
  EXPECT_NE(error.find("header"), std::string::npos) << error;
  // An instruction whose word count runs past the end.
  std::vector<uint32_t> words(kSpv_compute_shared_comp, kSpv_compute_shared_comp + 8);
  words[7] = (1000u << 16) | spv::OpName;
  Module b;
  EXPECT_FALSE(b.parse(words.data(), words.size(), &error));
  EXPECT_NE(error.find("at word 7"), std::string::npos) << error;
  // A zero word count.
  words[7] = 0;
  Module c;
  EXPECT_FALSE(c.parse(words.data(), words.size(), &error));
}

// Found by fuzz/spirv_module_fuzz.cpp (the inputs are fuzz/corpus/spirv/regress-enumerant-*): an operand the
// reader keeps as a C++ enum (capability, execution model, storage class) above 0x7fffffff is not SPIR-V, and
// storing it in the enum was undefined behaviour; it is a parse error.
TEST(SpirvModule, EnumerantPastTheEnumsIsAnError) {
  const size_t n = wordCount(kSpv_compute_shared_comp);
  for (auto [op, operand, what] :
       {std::tuple{spv::OpCapability, 1u, "OpCapability"}, std::tuple{spv::OpEntryPoint, 1u, "OpEntryPoint"},
        std::tuple{spv::OpTypePointer, 2u, "OpTypePointer"}}) {
    std::vector<uint32_t> words(kSpv_compute_shared_comp, kSpv_compute_shared_comp + n);
    size_t at = 5;
    while (at < n && spv::Op(words[at] & 0xffff) != op) at += words[at] >> 16;
    ASSERT_LT(at, n) << what;
    Module ok;
    std::string error;
    ASSERT_TRUE(ok.parse(words.data(), n, &error)) << error;
    words[at + operand] = 0xc3000000u;
    Module bad;
    EXPECT_FALSE(bad.parse(words.data(), n, &error)) << what;
    EXPECT_NE(error.find(what), std::string::npos) << error;
    EXPECT_NE(error.find("out of range"), std::string::npos) << error;
  }
}

TEST(SpirvModule, OpcodeNames) {
  EXPECT_EQ(opName(spv::OpIAdd), "OpIAdd");
  EXPECT_EQ(opName(spv::OpControlBarrier), "OpControlBarrier");
}

}  // namespace
}  // namespace vkrt::spirv
