// The ray query runtime (abi.hpp, "ray queries"): OpRayQuery*KHR on accel's query state (accel::RayQuery, kept in
// the shader's variable), and the scope a dispatch or launch hands its invocations, which resolves acceleration
// structure addresses once per dispatch through the caller (src/runtime, src/rt) and caches them.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>

#include "abi/abi.hpp"
#include "accel/accel.hpp"

namespace vkrt::exec {

// What resolves an acceleration structure address for a dispatch or launch (the device's registry).
class TopLevelResolver {
 public:
  virtual ~TopLevelResolver() = default;
  // The top-level structure at `address`, kept alive until the dispatch or launch ends, or null after reporting
  // (no structure there, a destroyed or a bottom-level one): the query finds nothing. Called per ray and per ray
  // query from any worker: it must take no lock, make no hash lookup and allocate nothing once an address has been
  // resolved (runtime's TopLevelTable resolves each address once per dispatch or launch).
  virtual const accel::Tlas* topLevel(uint64_t address) = 0;
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
