#include "exec/shader_debug.hpp"

#include <algorithm>
#include <atomic>
#include <cstdlib>

#include "exec/supervise.hpp"

namespace vkrt::exec {

namespace {

std::atomic<uint64_t> nextSerial{1};

// The thread's buffer in the command it last wrote to (by serial: a Job's address may be reused).
struct ThreadSlot {
  uint64_t serial = 0;
  void* buffer = nullptr;
};
thread_local ThreadSlot tlsSlot;

// Execution models (SPIR-V's numbers; exec does not include the SPIR-V headers).
constexpr uint32_t kModelVertex = 0, kModelFragment = 4, kModelGLCompute = 5;

std::atomic<AddressTableSource> addressSource{nullptr};

uint32_t argWords(const uint8_t* site) {
  uint32_t n = abi::siteWord(site, 2), words = 0;
  for (uint32_t i = 0; i < n; ++i) words += abi::siteWord(site, 3 + i) >> 16;
  return words;
}

}  // namespace

InvocationId invocationId(const abi::InvocationContext* ctx, uint32_t model) {
  InvocationId id;
  if (model == kModelGLCompute) {
    for (int i = 0; i < 3; ++i) id.v[i] = ctx->globalId[i];
  } else if (model == kModelVertex) {
    const auto* g = reinterpret_cast<const abi::GraphicsInvocation*>(ctx);
    id.v[0] = uint32_t(g->vertexIndex);
    id.v[1] = uint32_t(g->instanceIndex);
  } else if (model == kModelFragment) {
    const auto* g = reinterpret_cast<const abi::GraphicsInvocation*>(ctx);
    // The SPMD entry's lanes have their FragCoord in the quad's structure of arrays (lane = localIndex).
    const uint32_t lane = ctx->localIndex & 3;
    const float x = g->fragCoordSoa ? g->fragCoordSoa[lane] : g->fragCoord[0];
    const float y = g->fragCoordSoa ? g->fragCoordSoa[4 + lane] : g->fragCoord[1];
    std::memcpy(&id.v[0], &x, 4);
    std::memcpy(&id.v[1], &y, 4);
  } else {
    const auto* r = reinterpret_cast<const abi::RayInvocation*>(ctx);
    for (int i = 0; i < 3; ++i) id.v[i] = r->launchId[i];
  }
  return id;
}

ShaderMessages::ShaderMessages() : serial_(nextSerial.fetch_add(1, std::memory_order_relaxed)), limit_(printfLimit()) {}

uint32_t ShaderMessages::printfLimit() {
  static const uint32_t limit = [] {
    const char* v = std::getenv("VKRT_PRINTF_LIMIT");
    if (!v || !*v) return kDefaultPrintfLimit;
    char* end = nullptr;
    unsigned long n = std::strtoul(v, &end, 10);
    return end && *end == 0 && n <= UINT32_MAX ? uint32_t(n) : kDefaultPrintfLimit;
  }();
  return limit;
}

ShaderMessages::Buffer& ShaderMessages::local() {
  if (tlsSlot.serial == serial_) return *static_cast<Buffer*>(tlsSlot.buffer);
  std::lock_guard<std::mutex> lock(mutex_);
  Buffer& b = buffers_.emplace_back();
  tlsSlot.serial = serial_;
  tlsSlot.buffer = &b;
  return b;
}

void ShaderMessages::printf(const abi::InvocationContext* ctx, const uint8_t* site, const uint64_t* args) {
  Buffer& b = local();
  ++b.calls;
  // A thread keeps up to the command's limit (it may be the only one that prints); forEachPrintf applies the
  // limit to the command.
  if (b.kept >= limit_) return;
  ++b.kept;
  InvocationId id = invocationId(ctx, abi::siteWord(site, 1));
  b.words.push_back(reinterpret_cast<uintptr_t>(site));
  b.words.push_back(uint64_t(id.v[0]) | uint64_t(id.v[1]) << 32);
  b.words.push_back(id.v[2]);
  b.words.insert(b.words.end(), args, args + argWords(site));
}

void ShaderMessages::outOfBounds(const abi::InvocationContext* ctx, const uint8_t* site, uint64_t offset,
                                 uint64_t range, uint64_t element) {
  Buffer& b = local();
  for (const OutOfBoundsRecord& r : b.oob)
    if (r.site == site) return;
  b.oob.push_back({site, offset, range, element, invocationId(ctx, abi::siteWord(site, 1))});
}

void ShaderMessages::outOfBounds(const abi::InvocationContext* ctx, OutOfBoundsRecord r) {
  Buffer& b = local();
  for (const OutOfBoundsRecord& o : b.oob)
    if (o.site == r.site) return;
  r.id = invocationId(ctx, abi::siteWord(r.site, 1));
  b.oob.push_back(r);
}

bool ShaderMessages::empty() const {
  for (const Buffer& b : buffers_)
    if (b.calls || !b.oob.empty()) return false;
  return true;
}

void ShaderMessages::forEachPrintf(
    const std::function<void(const uint8_t* site, const InvocationId& id, const uint64_t* args)>& fn) const {
  uint64_t delivered = 0;
  for (const Buffer& b : buffers_) {
    for (size_t at = 0; at + 3 <= b.words.size() && delivered < limit_; ++delivered) {
      const auto* site = reinterpret_cast<const uint8_t*>(uintptr_t(b.words[at]));
      InvocationId id;
      id.v[0] = uint32_t(b.words[at + 1]);
      id.v[1] = uint32_t(b.words[at + 1] >> 32);
      id.v[2] = uint32_t(b.words[at + 2]);
      fn(site, id, b.words.data() + at + 3);
      at += 3 + argWords(site);
    }
  }
}

uint64_t ShaderMessages::droppedPrintfs() const {
  uint64_t calls = 0;
  for (const Buffer& b : buffers_) calls += b.calls;
  return calls > limit_ ? calls - limit_ : 0;
}

std::vector<OutOfBoundsRecord> ShaderMessages::outOfBoundsSites() const {
  std::vector<OutOfBoundsRecord> out;
  for (const Buffer& b : buffers_)
    for (const OutOfBoundsRecord& r : b.oob) {
      bool seen = false;
      for (const OutOfBoundsRecord& o : out) seen = seen || o.site == r.site;
      if (!seen) out.push_back(r);
    }
  return out;
}

void AddressTable::assign(std::vector<AddressRange> ranges) {
  std::sort(ranges.begin(), ranges.end(),
            [](const AddressRange& a, const AddressRange& b) { return a.begin < b.begin; });
  uint64_t maxEnd = 0;
  for (AddressRange& r : ranges) r.maxEnd = maxEnd = std::max(maxEnd, r.end);
  ranges_ = std::move(ranges);
}

const AddressRange* AddressTable::find(uint64_t address, uint64_t bytes) const {
  // The ranges beginning at or below the address; one of them holds the access exactly when the largest end among
  // them reaches its last byte (a range beginning above the address cannot hold it). Which one: back from the last,
  // past the aliasing ranges that end before (maxEnd says when none is left).
  const uint64_t end = address + bytes;
  if (end < address) return nullptr;
  auto it = std::upper_bound(ranges_.begin(), ranges_.end(), address,
                             [](uint64_t a, const AddressRange& r) { return a < r.begin; });
  while (it != ranges_.begin()) {
    --it;
    if (it->maxEnd < end) return nullptr;
    if (it->end >= end) return &*it;
  }
  return nullptr;
}

const AddressRange* AddressTable::nearest(uint64_t address) const {
  const AddressRange* best = nullptr;
  uint64_t bestDistance = UINT64_MAX;
  for (const AddressRange& r : ranges_) {  // (a report's, once per site: no need to be quick)
    uint64_t d = address < r.begin ? r.begin - address : address < r.end ? 0 : address - r.end + 1;
    if (d < bestDistance) {
      best = &r;
      bestDistance = d;
    }
  }
  return best;
}

void setAddressTableSource(AddressTableSource source) { addressSource.store(source, std::memory_order_release); }

const AddressTable& Job::addresses() {
  if (addressesReady_.load(std::memory_order_acquire)) return addresses_;
  std::lock_guard<std::mutex> lock(addressesMutex_);
  if (!addressesReady_.load(std::memory_order_relaxed)) {
    std::vector<AddressRange> ranges;
    if (AddressTableSource source = addressSource.load(std::memory_order_acquire)) source(owner_, &ranges);
    addresses_.assign(std::move(ranges));
    addressesReady_.store(true, std::memory_order_release);
  }
  return addresses_;
}

}  // namespace vkrt::exec

extern "C" {

// Outside a supervised task (a test calling compiled code directly) there is no command to collect for: dropped.
void vkrt_debug_printf(vkrt::abi::InvocationContext* ctx, const uint8_t* site, const uint64_t* args) {
  if (vkrt::exec::Job* job = vkrt::exec::runningJob()) job->messages.printf(ctx, site, args);
}

void vkrt_out_of_bounds(vkrt::abi::InvocationContext* ctx, const uint8_t* site, uint64_t offset, uint64_t range,
                        uint64_t element) {
  if (vkrt::exec::Job* job = vkrt::exec::runningJob()) job->messages.outOfBounds(ctx, site, offset, range, element);
}

const void* vkrt_address_table(vkrt::abi::InvocationContext*) {
  vkrt::exec::Job* job = vkrt::exec::runningJob();
  return job ? &job->addresses() : nullptr;  // compiled code run outside a command (tests): nothing to check against
}

uint32_t vkrt_check_address(vkrt::abi::InvocationContext* ctx, const void* table, const uint8_t* site, uint64_t address,
                            uint64_t bytes, uint64_t* cache) {
  using namespace vkrt::exec;
  const auto* t = static_cast<const AddressTable*>(table);
  if (!t) return 1;
  if (const AddressRange* r = t->find(address, bytes)) {
    cache[0] = r->begin;
    cache[1] = r->end;
    return 1;
  }
  OutOfBoundsRecord r;
  r.site = site;
  r.offset = address;
  r.range = bytes;
  if (const AddressRange* near = t->nearest(address)) {
    r.nearBegin = near->begin;
    r.nearSize = near->end - near->begin;
    r.nearObject = near->object;
  }
  if (Job* job = runningJob()) job->messages.outOfBounds(ctx, r);
  return 0;
}
}
