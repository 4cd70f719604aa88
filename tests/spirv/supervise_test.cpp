// Supervised shader execution below the Vulkan API (src/exec/supervise.hpp, the polls of
// src/spirv/cancellation_poll.cpp): a compiled loop stops at its next poll once the job is ended, the watchdog ends a
// job past its time limit, a fault in compiled code ends the job with its address, and a fault elsewhere is left to the
// handler before vkrt's.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <thread>

#include "abi/jit_code.hpp"
#include "exec/supervise.hpp"
#include "spirv/compute_harness.hpp"
#include "watchdog_fault.comp.spv.h"
#include "watchdog_fault_barrier.comp.spv.h"
#include "watchdog_spin.comp.spv.h"
#include "watchdog_spin_barrier.comp.spv.h"

namespace vkrt::testing {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// watchdog_spin.comp: invocation 70 (workgroup 1) loops forever; the watchdog ends the dispatch after 100 ms.
TEST(SpirvSupervision, TheWatchdogEndsAnEndlessLoopAtItsTimeLimit) {
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_watchdog_spin_comp)) << h.error;
  h.zeroBuffer<uint32_t>(0, 1 + 64 * 3);
  const uint32_t spinner = 70;
  std::memcpy(h.push, &spinner, 4);
  exec::Job job(nullptr, 100);
  h.job = &job;
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(h.run(3));
  const double took = secondsSince(t0);
  EXPECT_GE(took, 0.09);
  EXPECT_LT(took, 20.0);
  ASSERT_TRUE(job.aborted());
  EXPECT_EQ(job.abort().kind, exec::Abort::Timeout);
  EXPECT_EQ(job.abort().idKind, exec::Abort::Workgroup);
  EXPECT_EQ(job.abort().id[0], 1u);
}

// The limit is on progress: a job whose tasks keep completing runs past it (a long launch is not lost); one whose
// tasks stop completing is ended a limit after the last one.
TEST(SpirvSupervision, TheWatchdogLimitsTimeWithoutProgressNotTheJobsLength) {
  exec::Job job(nullptr, 100);
  auto sleep20 = [](void*) { std::this_thread::sleep_for(std::chrono::milliseconds(20)); };
  auto t0 = std::chrono::steady_clock::now();
  int ran = 0;
  while (secondsSince(t0) < 0.5 && exec::runSupervised(job, sleep20, nullptr)) ++ran;
  EXPECT_FALSE(job.aborted()) << "ended after " << ran << " tasks of 20 ms under a 100 ms limit";
  // Now nothing completes: the job ends within about a limit.
  auto t1 = std::chrono::steady_clock::now();
  while (!job.aborted() && secondsSince(t1) < 20) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(job.aborted());
  EXPECT_LT(secondsSince(t1), 5.0);
  EXPECT_FALSE(exec::runSupervised(job, sleep20, nullptr)) << "an ended job starts no task";
}

// The same with a barrier (fibers): a job ended from another thread (as vkDestroyDevice does) stops as well. The
// report names the invocation where each runs as a fiber of its own (the scalar path), the workgroup where a fiber
// runs a batch of them (SPMD).
void expectEndedFibersStop(bool spmd) {
  SpmdSetting setting(spmd);
  ComputeHarness h;
  ASSERT_TRUE(h.compile(kSpv_watchdog_spin_barrier_comp)) << h.error;
  h.zeroBuffer<uint32_t>(0, 1 + 64 * 2);
  const uint32_t spinner = 70;
  std::memcpy(h.push, &spinner, 4);
  int owner = 0;
  exec::Job job(&owner, 0);
  h.job = &job;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    exec::cancelJobsOf(&owner);
  });
  EXPECT_TRUE(h.run(2));
  canceller.join();
  ASSERT_TRUE(job.aborted());
  EXPECT_EQ(h.shader->spmdLanes != 0, spmd);
  EXPECT_EQ(job.abort().kind, exec::Abort::Cancelled);
  EXPECT_EQ(job.abort().idKind, spmd ? exec::Abort::Workgroup : exec::Abort::GlobalInvocation);
  EXPECT_EQ(job.abort().id[0], spmd ? 1u : 70u);
}

TEST(SpirvSupervision, AnEndedJobStopsTheLoopsOfItsFibers) { expectEndedFibersStop(false); }
TEST(SpirvSupervision, AnEndedJobStopsTheLoopsOfItsBatchFibers) { expectEndedFibersStop(true); }

// watchdog_fault*.comp: invocation 5 stores through address 0x1000 (nothing is mapped there); the other invocations
// of other workgroups may or may not have run, but those that ran before the fault wrote their index + 1.
void expectFaultRecovered(const uint32_t* words, size_t count, exec::Abort::IdKind kind, uint32_t id,
                          bool spmd = true) {
  SpmdSetting setting(spmd);
  ComputeHarness h;
  spirv::CompileRequest r;
  r.words = words;
  r.wordCount = count;
  r.hostSymbols = imageFunctionSymbols();
  h.shader = spirv::compile(r, &h.error);
  ASSERT_TRUE(h.shader) << h.error;
  if (h.shader->usesBarrier) {
    EXPECT_EQ(h.shader->spmdLanes != 0, spmd) << "fibers of batches (SPMD) or invocations";
  }
  std::vector<uint32_t> good(128, 0);
  struct {
    uint64_t good, wild;
    uint32_t faulter;
  } push{reinterpret_cast<uint64_t>(good.data()), 0x1000, 5};
  std::memcpy(h.push, &push, sizeof push);
  exec::Job job(nullptr, 0);
  h.job = &job;
  EXPECT_TRUE(h.run(2));
  ASSERT_TRUE(job.aborted());
  const exec::Abort& a = job.abort();
  EXPECT_EQ(a.kind, exec::Abort::Fault);
  EXPECT_EQ(a.signal, SIGSEGV);
  EXPECT_EQ(a.address, 0x1000u);
  EXPECT_TRUE(abi::JitCode::contains(uintptr_t(a.pc))) << "the faulting instruction is compiled shader code";
  EXPECT_EQ(a.idKind, kind);
  EXPECT_EQ(a.id[0], id);
  for (uint32_t i = 0; i < 128; ++i)
    if (good[i]) {
      EXPECT_EQ(good[i], i + 1) << i;
    }

  // The thread pool and the handler are still fine: the same dispatch without a faulting invocation runs.
  push.faulter = 1000;
  std::memcpy(h.push, &push, sizeof push);
  exec::Job clean(nullptr, 0);
  h.job = &clean;
  EXPECT_TRUE(h.run(2));
  EXPECT_FALSE(clean.aborted());
  for (uint32_t i = 0; i < 128; ++i) EXPECT_EQ(good[i], i + 1) << i;
}

TEST(SpirvSupervision, AFaultInCompiledCodeEndsTheJobWithItsAddress) {
  expectFaultRecovered(kSpv_watchdog_fault_comp, sizeof kSpv_watchdog_fault_comp / 4, exec::Abort::Workgroup, 0);
}

TEST(SpirvSupervision, AFaultInAFiberEndsTheJobWithItsInvocation) {
  expectFaultRecovered(kSpv_watchdog_fault_barrier_comp, sizeof kSpv_watchdog_fault_barrier_comp / 4,
                       exec::Abort::GlobalInvocation, 5, false);
}

TEST(SpirvSupervision, AFaultInABatchFiberEndsTheJobWithItsWorkgroup) {
  expectFaultRecovered(kSpv_watchdog_fault_barrier_comp, sizeof kSpv_watchdog_fault_barrier_comp / 4,
                       exec::Abort::Workgroup, 0);
}

// A fault outside compiled shader code, even in a supervised task, is not vkrt's to recover: the process dies as
// it would without vkrt (the default action, or the sanitizer's report).
TEST(SpirvSupervisionDeathTest, AFaultOutsideCompiledCodeIsNotRecovered) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        exec::Job job(nullptr, 0);
        exec::runSupervised(
            job, [](void*) { *reinterpret_cast<volatile int*>(uintptr_t(0x1000)) = 1; }, nullptr);
      },
      "");
}

TEST(JitCode, RangesAreFoundUntilRemoved) {
  uint32_t a = abi::JitCode::add(0x10000, 0x10100);
  uint32_t b = abi::JitCode::add(0x20000, 0x20010);
  ASSERT_LT(a, abi::JitCode::kSlots);
  ASSERT_LT(b, abi::JitCode::kSlots);
  EXPECT_TRUE(abi::JitCode::contains(0x10000));
  EXPECT_TRUE(abi::JitCode::contains(0x100ff));
  EXPECT_FALSE(abi::JitCode::contains(0x10100));
  EXPECT_TRUE(abi::JitCode::contains(0x20008));
  abi::JitCode::remove(a);
  EXPECT_FALSE(abi::JitCode::contains(0x10000));
  EXPECT_TRUE(abi::JitCode::contains(0x20008));
  abi::JitCode::remove(b);
  EXPECT_FALSE(abi::JitCode::contains(0x20008));
}

}  // namespace
}  // namespace vkrt::testing
