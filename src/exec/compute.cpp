#include "exec/compute.hpp"

#include <atomic>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "exec/fiber_group.hpp"
#include "exec/thread_pool.hpp"

namespace vkrt::exec {

namespace {

using abi::InvocationContext;

// Per worker thread: workgroup memory, the sink and the contexts of a workgroup with barriers, reused from dispatch to
// dispatch (the fiber stacks are exec/fiber_group.cpp's).
struct WorkerScratch {
  std::vector<uint64_t> workgroupMemory;  // 8-byte aligned; sized in bytes / 8
  std::vector<InvocationContext> contexts;
  std::vector<InvocationContext*> pointers;
  alignas(16) uint8_t sink[abi::kSinkBytes];
};

void noBarrier(InvocationContext*) {}

void setIds(InvocationContext& inv, const uint32_t wg[3], const uint32_t local[3], const uint32_t size[3]) {
  for (int i = 0; i < 3; ++i) {
    inv.workgroupId[i] = wg[i];
    inv.localId[i] = local[i];
    inv.globalId[i] = wg[i] * size[i] + local[i];
  }
  inv.localIndex = (local[2] * size[1] + local[1]) * size[0] + local[0];
}

// One workgroup (a task of runCompute's, run under supervision).
void runWorkgroup(const ComputeDispatch& d, const InvocationContext& proto, uint64_t g, std::atomic<bool>& failed) {
  const ComputeKernel& sh = d.kernel;
  const uint32_t* size = sh.localSize;
  const uint64_t invocations = uint64_t(size[0]) * size[1] * size[2];
  {
    thread_local WorkerScratch scratch;
    uint32_t wg[3] = {uint32_t(g % d.count[0]) + d.base[0], uint32_t(g / d.count[0] % d.count[1]) + d.base[1],
                      uint32_t(g / (uint64_t(d.count[0]) * d.count[1])) + d.base[2]};
    size_t wgBytes = sh.workgroupMemorySize;
    if (scratch.workgroupMemory.size() * 8 < wgBytes) scratch.workgroupMemory.resize((wgBytes + 7) / 8);
    uint8_t* wgMem = reinterpret_cast<uint8_t*>(scratch.workgroupMemory.data());
    if (wgBytes) std::memset(wgMem, 0, wgBytes);

    if (!sh.usesBarrier) {
      InvocationContext inv = proto;
      inv.workgroupMemory = wgMem;
      inv.sink = scratch.sink;
      if (sh.groupEntry) {
        // One call runs the workgroup: the compiled loop sets the invocation built-ins itself (a report can
        // name the workgroup only).
        for (int i = 0; i < 3; ++i) inv.workgroupId[i] = wg[i];
        setRunning(nullptr, inv.workgroupId, Abort::Workgroup);
        sh.groupEntry(&inv);
        return;
      }
      setRunning(nullptr, inv.globalId, Abort::GlobalInvocation);
      uint32_t local[3];
      for (local[2] = 0; local[2] < size[2]; ++local[2])
        for (local[1] = 0; local[1] < size[1]; ++local[1])
          for (local[0] = 0; local[0] < size[0]; ++local[0]) {
            setIds(inv, wg, local, size);
            sh.entry(&inv);
          }
      return;
    }

    // A fiber per invocation, or per batch of sh.batchLanes invocations (SPMD): the batch's context holds its first
    // invocation's ids (the compiled code takes the lanes from localIndex on).
    const bool batches = sh.batchLanes && sh.groupEntry;
    const uint64_t step = batches ? sh.batchLanes : 1;
    const uint64_t fibers = (invocations + step - 1) / step;
    if (scratch.contexts.size() < fibers) {
      scratch.contexts.resize(fibers);
      scratch.pointers.resize(fibers);
    }
    for (uint64_t f = 0; f < fibers; ++f) {
      InvocationContext& inv = scratch.contexts[f];
      inv = proto;
      inv.workgroupMemory = wgMem;
      inv.sink = scratch.sink;
      const uint64_t i = f * step;
      uint32_t local[3] = {uint32_t(i % size[0]), uint32_t(i / size[0] % size[1]),
                           uint32_t(i / (uint64_t(size[0]) * size[1]))};
      setIds(inv, wg, local, size);
      scratch.pointers[f] = &inv;
    }
    // A fault or a cancellation in one invocation ends the workgroup there (runFiberGroup calls abortTask()); a
    // batch's report names the workgroup, as vkrt_group's does.
    if (!runFiberGroup(batches ? sh.groupEntry : sh.entry, scratch.pointers.data(), uint32_t(fibers),
                       batches ? Abort::Workgroup : Abort::GlobalInvocation))
      failed = true;
  }
}

}  // namespace

bool runCompute(const ComputeDispatch& d) {
  const ComputeKernel& sh = d.kernel;
  const uint32_t* size = sh.localSize;
  uint64_t groups = uint64_t(d.count[0]) * d.count[1] * d.count[2];
  uint64_t invocations = uint64_t(size[0]) * size[1] * size[2];
  if (groups == 0 || invocations == 0) return true;
  bool ok = true;

  InvocationContext proto{};
  for (int i = 0; i < 3; ++i) {
    proto.numWorkgroups[i] = d.count[i];
    proto.workgroupSize[i] = size[i];
  }
  proto.resources = d.resources;
  proto.pushConstants = d.pushConstants;
  proto.rayQueries = d.rayQueries;
  proto.barrier = noBarrier;  // runFiberGroup sets its own for shaders with barriers
  std::optional<Job> ownJob;
  Job& job = d.job ? *d.job : ownJob.emplace(nullptr, 0);
  proto.cancel = reinterpret_cast<const uint32_t*>(&job.cancel);
  proto.cancelled = &cancelled;

  std::atomic<bool> failed{false};
  ThreadPool::instance().parallelFor(groups, [&](uint64_t g, unsigned) {
    auto task = [&] { runWorkgroup(d, proto, g, failed); };
    runSupervised(
        job, [](void* t) { (*static_cast<decltype(task)*>(t))(); }, &task);
  });
  if (failed) ok = false;
  return ok;
}

}  // namespace vkrt::exec
