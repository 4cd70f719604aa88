// exec::runFiberGroup (exec/fiber_group.hpp): every member reaches a barrier before any passes it, and a member that
// returned no longer takes part.
#include <gtest/gtest.h>

#include <vector>

#include "exec/fiber_group.hpp"

namespace vkrt::exec {
namespace {

// Each invocation (index in localIndex) passes `localIndex + 1` barriers, logging (invocation, phase) as it goes:
// invocation i returns after phase i.
struct Log {
  std::vector<std::pair<uint32_t, uint32_t>> events;
};

void steps(abi::InvocationContext* ctx) {
  Log* log = reinterpret_cast<Log*>(ctx->workgroupMemory);
  for (uint32_t phase = 0; phase <= ctx->localIndex; ++phase) {
    log->events.push_back({ctx->localIndex, phase});
    ctx->barrier(ctx);
  }
}

TEST(FiberGroup, EveryMemberReachesEachBarrierBeforeAnyPassesItAndEndedOnesDropOut) {
  Log log;
  constexpr uint32_t n = 4;
  abi::InvocationContext ctx[n] = {};
  abi::InvocationContext* ptrs[n];
  for (uint32_t i = 0; i < n; ++i) {
    ctx[i].localIndex = i;
    ctx[i].workgroupMemory = reinterpret_cast<uint8_t*>(&log);
    ptrs[i] = &ctx[i];
  }
  ASSERT_TRUE(runFiberGroup(&steps, ptrs, n));
  // Phase p is logged by invocations p..n-1, all before any phase p + 1.
  std::vector<std::pair<uint32_t, uint32_t>> expected;
  for (uint32_t phase = 0; phase < n; ++phase)
    for (uint32_t i = phase; i < n; ++i) expected.push_back({i, phase});
  EXPECT_EQ(log.events, expected);
  for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(ctx[i].executor != nullptr, true);
}

TEST(FiberGroup, AnEmptyGroupRunsNothing) { EXPECT_TRUE(runFiberGroup(&steps, nullptr, 0)); }

}  // namespace
}  // namespace vkrt::exec
