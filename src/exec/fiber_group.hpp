// Invocations that wait for each other: a compute workgroup with OpControlBarrier, a fragment quad taking
// derivatives. Each runs as a fiber (a stack of its own) on the calling worker; its context's `barrier` switches to
// the next unfinished fiber of the round (the round's last back to the group's scheduler, which starts the next
// round), so that every invocation reaches a barrier before any passes it. A fiber that returned no longer takes
// part: the others pass barriers without it.
#pragma once

#include <cstdint>

#include "abi/abi.hpp"
#include "exec/supervise.hpp"

namespace vkrt::exec {

// Runs entry(invocations[i]) for every i < count as fibers and returns when all have ended. Sets each context's
// `barrier` and `executor` (the other fields are the caller's). A fault or a cancellation in one invocation ends the
// group (the supervision of exec/supervise.hpp: abortTask()). Returns false, running nothing, when fiber stacks could
// not be allocated. Fiber stacks are per worker thread and reused. A report of a fault or a cancellation names the
// fiber's invocation (its context's globalId), or with `idKind` Workgroup its workgroup (a fiber that runs a batch
// of invocations: compute.cpp).
bool runFiberGroup(abi::ComputeEntry entry, abi::InvocationContext* const* invocations, uint32_t count,
                   Abort::IdKind idKind = Abort::GlobalInvocation);

}  // namespace vkrt::exec
