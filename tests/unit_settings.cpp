// The unit tests call the layers directly, without vkCreateDevice, which is where the driver applies
// VKRT_EMBREE_ISA, VKRT_JIT_CPU and VKRT_SPMD (runtime/device.cpp): this applies them the same way before any test
// runs, so that the test command's instruction-set matrix (tools/test.sh) reaches the unit tests too. A value that
// cannot apply fails the run: a matrix entry that silently ran the defaults would prove nothing.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "accel/accel.hpp"
#include "spirv/compiler.hpp"

namespace {

class InstructionSetSettings : public ::testing::Environment {
 public:
  void SetUp() override {
    std::string error;
    if (const char* isa = std::getenv("VKRT_EMBREE_ISA"); isa && *isa) {
      ASSERT_TRUE(vkrt::accel::setIsa(isa, &error)) << "VKRT_EMBREE_ISA=" << isa << ": " << error;
      ASSERT_EQ(std::string(vkrt::accel::isaInUse()), isa) << "this CPU cannot run Embree's " << isa << " kernels";
    }
    if (const char* cpu = std::getenv("VKRT_JIT_CPU"); cpu && *cpu) {
      ASSERT_TRUE(vkrt::spirv::setTargetCpu(cpu, &error)) << "VKRT_JIT_CPU=" << cpu << ": " << error;
    }
    if (const char* spmd = std::getenv("VKRT_SPMD"); spmd && *spmd) vkrt::spirv::setSpmd(std::string(spmd) != "0");
  }
};

const ::testing::Environment* const kSettings = ::testing::AddGlobalTestEnvironment(new InstructionSetSettings);

}  // namespace
