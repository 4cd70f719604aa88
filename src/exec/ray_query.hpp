// The ray query runtime (abi.hpp, "ray queries"): OpRayQuery*KHR on accel's query state (accel::RayQuery, kept in
// the shader's variable), and the scope a dispatch or launch hands its invocations, which resolves acceleration
// structure addresses once per dispatch through the caller (src/runtime, src/rt) and caches them.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "abi/abi.hpp"
#include "accel/accel.hpp"

namespace vkrt::exec {

// What resolves the acceleration structure addresses of one dispatch or launch (traceRayEXT and ray queries alike),
// each once: its caller (src/runtime, src/rt) supplies the device's structures (snapshot, resolve) and the reports
// (missed). On first use it takes the addresses of the structures that may hold a top level and a range index over
// them: the address span cut into equal ranges (a power of two of them). Where ranges of two or four times the
// number of entries hold at most one entry each (the addresses come from allocations, so they spread over the span),
// the entries are laid out one per range ("direct"): a resolution reads its address's range's entry, one load before
// the structure. Otherwise the entries are sorted by address, the ranges as many as the entries, each range holding
// the index of its first entry, and a resolution searches the entries from its range's first in a fixed number of
// halving steps (conditional moves), the same for every range of the work: enough for its fullest range. Either
// way it takes no lock, makes no virtual call and has no loop whose length the address decides (a search as long as
// each range, as before, mispredicted its end on rays that pick structures at random); however the addresses
// cluster, the search is never longer than a bisection of the whole array. An entry holds its address and what it
// resolved to side by side, so the entry's load brings the structure too. The snapshot resolves what it can at once
// (the caller's one pass over the device's structures); any other address is resolved through resolve() the first
// time an invocation meets it (under the table's lock), and an address that denotes no built top level resolves to
// null, also once, the work's first such miss reported through missed(). So no invocation takes a lock, looks up a
// hash table or allocates per ray, however many structures the work reaches (at most one resolution per structure
// and per work).
class TopLevelResolver {
 public:
  virtual ~TopLevelResolver() = default;

  // The top-level structure at `address`, alive until the work ends, or null (no structure there, a destroyed or a
  // bottom-level one: the ray misses, the query finds nothing). Called per ray and per ray query from any worker.
  const accel::Tlas* topLevel(uint64_t address) {
    if (!ready_.load(std::memory_order_acquire)) [[unlikely]]
      takeSnapshot();
    const ptrdiff_t i = count_ ? locate(entries_.get(), count_, firstOf_.get(), index_, address) : -1;
    if (i < 0) [[unlikely]]
      return miss(address);
    const accel::Tlas* t = entries_[size_t(i)].tlas.load(std::memory_order_acquire);
    if (!t) [[unlikely]]
      t = resolveEntry(entries_[size_t(i)]);
    return t != unresolvable() ? t : miss(address);
  }

  // One structure's address and, once resolved, the structure (null before; unresolvable() for an address that
  // denotes no built top level).
  struct Entry {
    uint64_t address = 0;
    std::atomic<const accel::Tlas*> tlas{nullptr};
  };
  // The range index over `count` (> 0) addresses sorted in increasing order: the lowest address, the shift that
  // cuts their span into `ranges` ranges (a power of two), and how entries are found. Direct: `ranges` entries, the
  // one of range r at r (an entry of no address there where the range holds none). Searched: the `count` entries
  // sorted, ranges the power of two at or above count, and the number of halving steps that search the fullest
  // range (ceil(log2) of its entries); firstOf[r] (r in 0..ranges) is the index of the first entry at or past
  // range r.
  struct RangeIndex {
    uint64_t lo = 0;
    unsigned shift = 0;
    unsigned steps = 0;
    uint64_t ranges = 0;
    bool direct = false;
    // The entries a search may read past the last one: sentinels (an address above every other, no structure).
    // From a range's first entry (at most the count) the steps move at most 2^steps - 1 entries on.
    size_t padding() const { return size_t(1) << steps; }
    // The entries to allocate for `count` addresses.
    size_t entries(size_t count) const { return direct ? size_t(ranges) : count + padding(); }
  };
  // The index for the sorted `addresses`; fills `firstOf` (room for count * 2 + 1 entries) when it is not direct.
  static RangeIndex rangeIndex(const uint64_t* addresses, size_t count, uint32_t* firstOf);
  // Lays the sorted `addresses` out in `entries` (index.entries(count) of them) as `index` finds them; each
  // address's entry is at slot(index, i, address).
  static void layOut(const RangeIndex& index, const uint64_t* addresses, size_t count, Entry* entries);
  static size_t slot(const RangeIndex& index, size_t i, uint64_t address) {
    return index.direct ? size_t((address - index.lo) >> index.shift) : i;
  }
  // The entry holding `address` among `count` entries laid out by layOut with the range index `firstOf`, or -1:
  // the search topLevel does, for the tests.
  static ptrdiff_t locate(const Entry* entries, size_t count, const uint32_t* firstOf, const RangeIndex& index,
                          uint64_t address) {
    if (address < index.lo) return -1;
    const uint64_t r = (address - index.lo) >> index.shift;
    if (r >= index.ranges) return -1;
    if (index.direct) return entries[r].address == address ? ptrdiff_t(r) : -1;
    // The first entry at or above `address` among the 2^steps entries from the range's first, the range's whole
    // (entries past it have higher addresses, the sentinels the highest), or the last of them when all lie below
    // (then no entry holds `address`): each step moves past a half that lies below, as a conditional move.
    size_t p = firstOf[r];
    for (unsigned s = index.steps; s-- > 0;) {
      const size_t half = size_t(1) << s;
      p = entries[p + half - 1].address < address ? p + half : p;
    }
    return p < count && entries[p].address == address ? ptrdiff_t(p) : -1;
  }

  // What snapshot() fills: every structure the work may reach as a top level, by address.
  struct Snapshot {
    // Each structure's address, in increasing order, and with it the structure where it is known already (the rest
    // go through resolve()).
    std::vector<std::pair<uint64_t, std::shared_ptr<const accel::Tlas>>> structures;
  };

 protected:
  // Called once per work, on first use, under the table's lock.
  virtual void snapshot(Snapshot* out) = 0;
  // The built top level at `address` (one of the snapshot's, not known then), or null; once per address, under the
  // table's lock.
  virtual std::shared_ptr<const accel::Tlas> resolve(uint64_t address) = 0;
  // The work's first address that resolved to no top level (once per work).
  virtual void missed(uint64_t address) = 0;

 private:
  static const accel::Tlas* unresolvable() { return reinterpret_cast<const accel::Tlas*>(uintptr_t(1)); }
  void takeSnapshot();
  const accel::Tlas* resolveEntry(Entry& entry);
  const accel::Tlas* miss(uint64_t address) {
    // A load first: rays that miss after the first write nothing, so they do not contend for the flag's cache line.
    if (!missed_.load(std::memory_order_relaxed) && !missed_.exchange(true, std::memory_order_relaxed)) missed(address);
    return nullptr;
  }

  std::atomic<bool> ready_{false};  // the snapshot is taken (a load per resolution; std::call_once costs TLS writes)
  size_t count_ = 0;
  std::unique_ptr<Entry[]> entries_;     // laid out by layOut
  std::unique_ptr<uint32_t[]> firstOf_;  // the range index of a searched layout (rangeIndex)
  RangeIndex index_;
  std::mutex mutex_;                                      // the snapshot, resolutions, kept_
  std::vector<std::shared_ptr<const accel::Tlas>> kept_;  // one per resolved structure, alive until the work ends
  std::atomic<bool> missed_{false};
};

// The scope of one dispatch or launch. Thread-safe: any worker may resolve.
class RayQueryScope : public abi::RayQueryScope {
 public:
  explicit RayQueryScope(TopLevelResolver* resolver);
  const accel::Tlas* topLevel(uint64_t address) { return resolver_ ? resolver_->topLevel(address) : nullptr; }

 private:
  TopLevelResolver* resolver_;
};

const abi::RayQueryRuntime& rayQueryRuntime();

}  // namespace vkrt::exec
