// The range index over a launch's sorted top-level addresses (exec/ray_query.hpp, TopLevelResolver):
// every address is found at its own entry, and no other address is found, whatever the spread of the addresses
// (evenly spaced as allocations give them, clustered, one, two, spanning all of uint64_t).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "exec/ray_query.hpp"

namespace vkrt {
namespace {

// Checks locate() against std::lower_bound (and the layout's slot) for each address, its neighbours and `probes` random
// values. `expectedSteps`, where not -1: the search's steps the spread of the addresses calls for.
void checkIndex(std::vector<uint64_t> addresses, uint32_t seed, size_t probes = 2000, int expectedSteps = -1,
                int expectedDirect = -1) {
  std::sort(addresses.begin(), addresses.end());
  addresses.erase(std::unique(addresses.begin(), addresses.end()), addresses.end());
  const size_t n = addresses.size();
  std::vector<uint32_t> firstOf(2 * n + 1, 0xFFFFFFFFu);
  const exec::TopLevelResolver::RangeIndex index =
      exec::TopLevelResolver::rangeIndex(addresses.data(), n, firstOf.data());
  std::vector<exec::TopLevelResolver::Entry> entries(index.entries(n));
  exec::TopLevelResolver::layOut(index, addresses.data(), n, entries.data());
  const uint64_t ranges = index.ranges;
  ASSERT_EQ(ranges & (ranges - 1), 0u) << "a power of two";
  ASSERT_EQ(index.lo, addresses.front());
  ASSERT_LT((addresses.back() - addresses.front()) >> index.shift, ranges) << "the last address falls in a range";
  // The ranges of each address.
  std::vector<uint64_t> rangeOf(n);
  for (size_t i = 0; i < n; ++i) rangeOf[i] = (addresses[i] - index.lo) >> index.shift;
  const bool alone = std::adjacent_find(rangeOf.begin(), rangeOf.end()) == rangeOf.end();
  if (index.direct) {
    // Twice or four times the power of two at or above n, each address alone in its range.
    ASSERT_GE(ranges, 2 * n);
    ASSERT_LT(ranges, 8 * n);
    ASSERT_TRUE(alone);
    ASSERT_EQ(index.entries(n), ranges);
  } else {
    ASSERT_GE(ranges, n);
    ASSERT_LT(ranges, 2 * n);
    // Direct layouts were possible neither at twice nor at four times as many ranges.
    for (unsigned finer : {1u, 2u}) {
      bool shared = false;
      for (size_t i = 1; i < n; ++i)
        shared |= (addresses[i] - index.lo) >> (index.shift - std::min(finer, index.shift)) ==
                  (addresses[i - 1] - index.lo) >> (index.shift - std::min(finer, index.shift));
      ASSERT_TRUE(shared || index.shift < finer) << "a direct layout at " << (1u << finer) << " times the ranges";
    }
    uint32_t fullest = 0;
    for (uint64_t r = 0; r < ranges; ++r) {
      ASSERT_LE(firstOf[r], firstOf[r + 1]) << "range " << r;
      fullest = std::max(fullest, firstOf[r + 1] - firstOf[r]);
    }
    ASSERT_EQ(firstOf[ranges], n);
    // The steps search the fullest range, and take no more halvings than it needs.
    ASSERT_GE(uint64_t(1) << index.steps, fullest);
    ASSERT_TRUE(index.steps == 0 || (uint64_t(1) << (index.steps - 1)) < fullest) << index.steps << " steps";
  }
  if (expectedDirect >= 0) {
    ASSERT_EQ(index.direct, expectedDirect == 1);
  }
  if (expectedSteps >= 0) {
    ASSERT_EQ(index.steps, unsigned(expectedSteps));
  }

  auto expected = [&](uint64_t a) -> ptrdiff_t {
    auto it = std::lower_bound(addresses.begin(), addresses.end(), a);
    if (it == addresses.end() || *it != a) return -1;
    return ptrdiff_t(exec::TopLevelResolver::slot(index, size_t(it - addresses.begin()), a));
  };
  auto check = [&](uint64_t a) {
    ASSERT_EQ(exec::TopLevelResolver::locate(entries.data(), n, firstOf.data(), index, a), expected(a))
        << "address 0x" << std::hex << a << " among " << std::dec << n;
  };
  for (uint64_t a : addresses) {
    check(a);
    check(a - 1);
    check(a + 1);
  }
  check(0);
  check(~uint64_t(0));
  // Each range's first address and the one below it (the direct layout's filler of an empty range).
  for (uint64_t r = 0; r < std::min<uint64_t>(ranges, 1 << 14); ++r) {
    check(index.lo + (r << index.shift));
    check(index.lo + (r << index.shift) - 1);
  }
  std::mt19937_64 rng(seed);
  const uint64_t lo = addresses.front(), span = addresses.back() - lo;
  for (size_t k = 0; k < probes; ++k) {
    check(rng());
    if (span) check(lo + rng() % span);
  }
}

TEST(TopLevelTableIndex, EvenlySpacedAddressesAreEachFoundAndNothingElse) {
  std::vector<uint64_t> a;
  for (uint64_t i = 0; i < 1000; ++i) a.push_back(0x567000000000ull + i * 4096);
  checkIndex(a, 1, 2000, 0, 1);  // one address per range: direct
  // Pairs 256 bytes apart, 8 KiB between pairs: 1,000 addresses in 1,024 ranges of 4 KiB, some holding a pair.
  for (uint64_t i = 0; i < 1000; ++i) a[i] = 0x567000000000ull + (i / 2) * 8192 + (i % 2) * 256;
  checkIndex(a, 7, 2000, 1, 0);
}

TEST(TopLevelTableIndex, AddressesAloneOnlyInFinerRangesAreLaidOutDirectly) {
  // 1,024 addresses, pairs 700 bytes apart, 4 KiB between pairs: twice as many ranges as the power of two (1 KiB
  // each) hold a pair in one, four times as many (512 bytes) one address each.
  std::vector<uint64_t> a;
  for (uint64_t i = 0; i < 1024; ++i) a.push_back(0x7f0000000000ull + (i / 2) * 4096 + (i % 2) * 700);
  checkIndex(a, 8, 2000, 0, 1);
  std::vector<uint32_t> firstOf(2 * a.size() + 1);
  EXPECT_EQ(exec::TopLevelResolver::rangeIndex(a.data(), a.size(), firstOf.data()).ranges, 4096u);
  // 400 bytes apart: no direct layout; the searched one, 1,024 ranges of 2 KiB, every other one holding a pair.
  for (uint64_t i = 0; i < 1024; ++i) a[i] = 0x7f0000000000ull + (i / 2) * 4096 + (i % 2) * 400;
  checkIndex(a, 9, 2000, 1, 0);
}

TEST(TopLevelTableIndex, ClusteredAddressesAreEachFoundAndNothingElse) {
  // Most addresses in one cluster, a few far away: one range holds nearly all entries, and its bisection finds them.
  std::vector<uint64_t> a;
  for (uint64_t i = 0; i < 500; ++i) a.push_back(0x1000 + i * 256);
  a.push_back(0x567000000000ull);
  a.push_back(0x7fff00000000ull);
  checkIndex(a, 2, 2000, 9, 0);  // 500 entries in the first range
}

TEST(TopLevelTableIndex, RandomAddressesOfEverySpanAreEachFoundAndNothingElse) {
  std::mt19937_64 rng(3);
  for (size_t n : {1, 2, 3, 7, 16, 17, 255, 256, 257, 4096}) {
    std::vector<uint64_t> a;
    for (size_t i = 0; i < n; ++i) a.push_back(rng() >> (i % 3 == 0 ? 0 : 20));
    checkIndex(a, uint32_t(n), 200);
  }
}

TEST(TopLevelTableIndex, TheExtremesOfTheAddressSpaceAreFound) {
  checkIndex({0, ~uint64_t(0)}, 4);
  checkIndex({1, ~uint64_t(0) - 1, ~uint64_t(0)}, 5);
  checkIndex({0x567000001000ull}, 6);
}

// A resolver over `addresses` (sorted, distinct): every third is in the snapshot without its structure (resolved on
// first use, to a structure or, every sixth, to none), the rest with theirs. Structures are stand-in pointers, never
// dereferenced by the resolver.
class StubResolver : public exec::TopLevelResolver {
 public:
  explicit StubResolver(std::vector<uint64_t> addresses) : addresses_(std::move(addresses)) {}
  // What topLevel must answer for `a`.
  const accel::Tlas* expected(uint64_t a) const {
    auto it = std::lower_bound(addresses_.begin(), addresses_.end(), a);
    if (it == addresses_.end() || *it != a) return nullptr;
    const size_t i = size_t(it - addresses_.begin());
    return i % 6 == 3 ? nullptr : structure(i);
  }
  size_t resolves = 0, misses = 0;

 protected:
  void snapshot(Snapshot* out) override {
    for (size_t i = 0; i < addresses_.size(); ++i)
      out->structures.emplace_back(addresses_[i], i % 3 == 0 ? nullptr : stub(i));
  }
  std::shared_ptr<const accel::Tlas> resolve(uint64_t address) override {
    ++resolves;
    const size_t i = size_t(std::lower_bound(addresses_.begin(), addresses_.end(), address) - addresses_.begin());
    return i % 6 == 3 ? nullptr : stub(i);
  }
  void missed(uint64_t) override { ++misses; }

 private:
  static const accel::Tlas* structure(size_t i) { return reinterpret_cast<const accel::Tlas*>(0x10000 + 16 * i); }
  static std::shared_ptr<const accel::Tlas> stub(size_t i) {
    return std::shared_ptr<const accel::Tlas>(structure(i), [](const accel::Tlas*) {});
  }
  std::vector<uint64_t> addresses_;
};

TEST(TopLevelTableIndex, TheResolverAnswersEveryAddressAndResolvesEachOnce) {
  // Ranges of one entry, of two and of many, and empty ones, with structures the snapshot knew and ones resolved on
  // first use (to a structure or to none): the right answer for every address and its neighbours, twice over; each
  // address the snapshot left unresolved resolved once; the first miss reported once.
  std::vector<uint64_t> mixed;
  for (uint64_t i = 0; i < 300; ++i) mixed.push_back(0x567000000000ull + (i << 20));
  for (uint64_t i = 0; i < 100; ++i) mixed.push_back(0x567019000000ull + (i / 2) * 8192 + (i % 2) * 256);
  for (uint64_t i = 0; i < 50; ++i) mixed.push_back(0x567019200000ull + i * 16);
  // And addresses that allocations space evenly, laid out directly.
  std::vector<uint64_t> even;
  for (uint64_t i = 0; i < 450; ++i) even.push_back(0x567000000000ull + i * 12288);
  for (const std::vector<uint64_t>* a : {&mixed, &even}) {
    std::vector<uint32_t> firstOf(2 * a->size() + 1);
    ASSERT_EQ(exec::TopLevelResolver::rangeIndex(a->data(), a->size(), firstOf.data()).direct, a == &even);
    StubResolver r(*a);
    for (int pass = 0; pass < 2; ++pass) {
      for (uint64_t x : *a) {
        ASSERT_EQ(r.topLevel(x), r.expected(x)) << "address 0x" << std::hex << x << " pass " << pass;
        ASSERT_EQ(r.topLevel(x + 8), r.expected(x + 8)) << "address 0x" << std::hex << x + 8;
        ASSERT_EQ(r.topLevel(x - 8), r.expected(x - 8)) << "address 0x" << std::hex << x - 8;
      }
    }
    EXPECT_EQ(r.topLevel(0), nullptr);
    EXPECT_EQ(r.topLevel(~uint64_t(0)), nullptr);
    EXPECT_EQ(r.resolves, a->size() / 3);
    EXPECT_EQ(r.misses, 1u);
  }
}

}  // namespace
}  // namespace vkrt
