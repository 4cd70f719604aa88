#include "runtime/shader_messages.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "runtime/buffer.hpp"
#include "runtime/command_buffer.hpp"
#include "runtime/device.hpp"
#include "runtime/instance.hpp"
#include "runtime/report.hpp"
#include "spirv/shader_debug.hpp"

namespace vkrt {

namespace {

// VKRT_PRINTF: where printf text goes.
enum class PrintfTarget { Auto, Stdout, None };

PrintfTarget printfTarget() {
  static const PrintfTarget t = [] {
    const char* v = std::getenv("VKRT_PRINTF");
    if (v && std::strcmp(v, "stdout") == 0) return PrintfTarget::Stdout;
    if (v && std::strcmp(v, "none") == 0) return PrintfTarget::None;
    return PrintfTarget::Auto;
  }();
  return t;
}

std::string objectText(const Object* o) {
  if (!o) return "";
  char buf[96];
  std::snprintf(buf, sizeof buf, "%s 0x%llx", objectTypeName(o->objectType),
                static_cast<unsigned long long>(o->handleValue()));
  std::string s = buf;
  std::string name = o->debugName();
  if (!name.empty()) s += " '" + name + "'";
  return s;
}

// spv::ExecutionModel's names for a message.
const char* stageName(uint32_t model) {
  switch (model) {
    case spv::ExecutionModelVertex: return "vertex";
    case spv::ExecutionModelFragment: return "fragment";
    case spv::ExecutionModelGLCompute: return "compute";
    case spv::ExecutionModelRayGenerationKHR: return "ray generation";
    case spv::ExecutionModelIntersectionKHR: return "intersection";
    case spv::ExecutionModelAnyHitKHR: return "any-hit";
    case spv::ExecutionModelClosestHitKHR: return "closest-hit";
    case spv::ExecutionModelMissKHR: return "miss";
    case spv::ExecutionModelCallableKHR: return "callable";
    default: return "unknown";
  }
}

std::string invocationText(uint32_t model, const exec::InvocationId& id) {
  char buf[128];
  const uint32_t* v = id.v;
  if (model == spv::ExecutionModelGLCompute) {
    std::snprintf(buf, sizeof buf, "global invocation (%u, %u, %u)", v[0], v[1], v[2]);
  } else if (model == spv::ExecutionModelVertex) {
    std::snprintf(buf, sizeof buf, "vertex index %d, instance %d", int32_t(v[0]), int32_t(v[1]));
  } else if (model == spv::ExecutionModelFragment) {
    float x, y;
    std::memcpy(&x, &v[0], 4);
    std::memcpy(&y, &v[1], 4);
    std::snprintf(buf, sizeof buf, "fragment at (%g, %g)", x, y);
  } else {
    std::snprintf(buf, sizeof buf, "launch id (%u, %u, %u)", v[0], v[1], v[2]);
  }
  return buf;
}

std::string shaderText(uint32_t model, const char* entry, const Object* pipeline) {
  std::string s = std::string(stageName(model)) + " shader \"" + entry + "\"";
  if (pipeline) s += " of " + objectText(pipeline);
  return s;
}

// VKRT_SHADER_CHECKS=bda: a PhysicalStorageBuffer access outside every live buffer with a device address, or across
// one's end (undefined behaviour in Vulkan: vkrt reads zeros or drops it).
std::string addressAccessText(uint32_t kind, uint32_t bytes, const exec::OutOfBoundsRecord& r) {
  char buf[320];
  const char* what = kind == abi::kAccessLoad ? "load" : kind == abi::kAccessStore ? "store" : "atomic";
  std::snprintf(buf, sizeof buf, "%s of %u bytes at device address 0x%llx", what, bytes,
                static_cast<unsigned long long>(r.offset));
  std::string text = buf;
  if (r.nearSize == 0) {
    text += " is in no live buffer with a device address (none is bound)";
  } else {
    const uint64_t end = r.nearBegin + r.nearSize;
    const auto ull = [](uint64_t v) { return static_cast<unsigned long long>(v); };
    if (r.offset >= r.nearBegin && r.offset < end) {
      std::snprintf(buf, sizeof buf, " crosses the end of the buffer at [0x%llx, 0x%llx) (%llu bytes; offset %llu)",
                    ull(r.nearBegin), ull(end), ull(r.nearSize), ull(r.offset - r.nearBegin));
    } else {
      const bool after = r.offset >= end;
      std::snprintf(buf, sizeof buf,
                    " is in no live buffer with a device address: it lies %llu bytes %s the nearest, [0x%llx, 0x%llx) "
                    "(%llu bytes)",
                    ull(after ? r.offset - end : r.nearBegin - r.offset), after ? "past the end of" : "before",
                    ull(r.nearBegin), ull(end), ull(r.nearSize));
    }
    text += buf;
    withAddressBuffer(r.nearObject, [&](const Buffer& b) { text += ", " + objectText(&b); });
  }
  return text + (kind == abi::kAccessLoad    ? "; the load reads zeros"
                 : kind == abi::kAccessStore ? "; the store is dropped"
                                             : "; the atomic acts on nothing");
}

// VKRT_SHADER_CHECKS=image: an image or texel buffer access outside the view (robustImageAccess: reads return zeros,
// writes and atomics are dropped).
std::string imageAccessText(uint32_t kind, const exec::OutOfBoundsRecord& r, const std::string& resource) {
  static const char* const names[] = {"OpImageRead", "OpImageWrite", "OpImageFetch", "OpImageTexelPointer",
                                      "OpImageRead", "OpImageWrite", "OpImageFetch", "OpImageTexelPointer"};
  const uint32_t at = kind - abi::kAccessImageRead;
  const bool texel = kind >= abi::kAccessTexelRead;
  const bool write = kind == abi::kAccessImageWrite || kind == abi::kAccessTexelWrite;
  const bool atomic = kind == abi::kAccessImageAtomic || kind == abi::kAccessTexelAtomic;
  char buf[320];
  auto ll = [](int64_t v) { return static_cast<long long>(v); };
  auto ull = [](uint64_t v) { return static_cast<unsigned long long>(v); };
  if (texel) {
    std::snprintf(buf, sizeof buf, "%s at texel %lld is outside the %llu texels of the texel buffer", names[at],
                  ll(r.coord[0]), ull(r.extent[0]));
  } else {
    std::snprintf(buf, sizeof buf,
                  "%s at (%lld, %lld, %lld), layer %lld, level %lld is outside the view (level %lld: %llux%llux%llu, "
                  "%llu layers; %llu levels)",
                  names[at], ll(r.coord[0]), ll(r.coord[1]), ll(r.coord[2]), ll(r.coord[3]), ll(r.coord[4]),
                  ll(r.coord[4]), ull(r.extent[0]), ull(r.extent[1]), ull(r.extent[2]), ull(r.extent[3]),
                  ull(r.extent[4]));
  }
  std::string text = buf;
  if (!resource.empty()) text += " (" + resource + ")";
  return text + (write    ? "; the write is dropped"
                 : atomic ? "; the atomic acts on nothing"
                          : "; the read returns zeros");
}

void deliverOutOfBounds(const CommandBuffer* cb, const Object* pipeline, const char* fn,
                        const exec::OutOfBoundsRecord& r, const DescriptorNamer& namer) {
  const spirv::AccessSiteInfo s = spirv::readAccessSite(r.site);
  char buf[256];
  std::string resource;
  if (s.set != ~0u) {
    std::snprintf(buf, sizeof buf, "set %u, binding %u, element %llu", s.set, s.binding,
                  static_cast<unsigned long long>(r.element));
    resource = buf;
    if (!s.variable.empty()) resource += ", variable \"" + s.variable + "\"";
    std::string object = namer ? namer(s.set, s.binding, r.element) : std::string();
    if (!object.empty()) resource += ", " + object;
  }
  std::string what;
  if (s.kind >= abi::kAccessImageRead) {
    what = imageAccessText(s.kind, r, resource);
  } else if (s.set == ~0u && s.kind != abi::kAccessDescriptorIndex) {
    what = addressAccessText(s.kind, s.bytes, r);
  } else if (s.kind == abi::kAccessDescriptorIndex) {
    std::snprintf(buf, sizeof buf, "descriptor index %llu is past the %llu descriptors bound",
                  static_cast<unsigned long long>(r.offset), static_cast<unsigned long long>(r.range));
    what = std::string(buf) + " (" + resource + "); the access uses a null descriptor";
  } else {
    const char* kind = s.kind == abi::kAccessLoad ? "load" : s.kind == abi::kAccessStore ? "store" : "atomic";
    std::snprintf(buf, sizeof buf, "%s of %u bytes at offset %llu is outside the %llu bytes in range", kind, s.bytes,
                  static_cast<unsigned long long>(r.offset), static_cast<unsigned long long>(r.range));
    what = std::string(buf) + " of the buffer (" + resource + "); " +
           (s.kind == abi::kAccessLoad    ? "the load reads zeros"
            : s.kind == abi::kAccessStore ? "the store is dropped"
                                          : "the atomic leaves the buffer as it is");
  }
  std::string where;
  if (!s.file.empty()) {
    std::snprintf(buf, sizeof buf, " at line %u", s.line);
    where = "in file " + s.file + buf;
    if (s.column) where += ", column " + std::to_string(s.column);
  } else if (s.wordOffset) {
    where = "at SPIR-V word offset " + std::to_string(s.wordOffset) + " (the module has no line information for it)";
  } else {
    where = "(no line information)";
  }
  // Undefined behaviour on a device without robustBufferAccess; with it, defined (zeros, dropped writes) but
  // rarely what the shader meant.
  const Device* dev = cb->device;
  // Images: defined with robustImageAccess. A device address outside every buffer is undefined whatever the features.
  const bool image = s.kind >= abi::kAccessImageRead;
  const bool address = !image && s.set == ~0u && s.kind != abi::kAccessDescriptorIndex;
  const bool defined =
      dev && !address && dev->enabled(image ? Feature::robustImageAccess : Feature::robustBufferAccess);
  Severity severity = defined ? Severity::Info : Severity::Warning;
  std::string body = std::string(fn) + ": " + shaderText(s.model, s.entryName.c_str(), pipeline) + " " + where + ", " +
                     invocationText(s.model, r.id) + ": " + what;
  reportWithId(cb, severity, kOutOfBoundsMessageId, 0, body);
}

}  // namespace

DescriptorNamer descriptorNamer(const spirv::CompiledShader& shader, const abi::ResourceSlot* slots) {
  return [&shader, slots](uint32_t set, uint32_t binding, uint64_t element) -> std::string {
    if (!slots) return "";
    for (size_t i = 0; i < shader.resources.size(); ++i) {
      const spirv::ResourceBinding& r = shader.resources[i];
      if (r.set != set || r.binding != binding) continue;
      if (element >= slots[i].count || !slots[i].records) return "";
      return objectText(static_cast<const Object*>(slots[i].records[element].object));
    }
    return "";
  };
}

void deliverShaderMessages(const CommandBuffer* cb, const Object* pipeline, const char* fn,
                           const exec::ShaderMessages& messages, const DescriptorNamer& namer) {
  if (messages.empty()) return;
  const PrintfTarget target = printfTarget();
  const bool toStdout = target == PrintfTarget::Stdout ||
                        (target == PrintfTarget::Auto && !(cb->instance && cb->instance->hasMessengers()));
  if (target != PrintfTarget::None) {
    messages.forEachPrintf([&](const uint8_t* site, const exec::InvocationId& id, const uint64_t* args) {
      std::string text = spirv::formatPrintf(site, args);
      if (toStdout) {
        std::fwrite(text.data(), 1, text.size(), stdout);
        std::fputc('\n', stdout);
        return;
      }
      // As the validation layer's: the text after the last " | " (handlers cut it there).
      uint32_t model = abi::siteWord(site, 1);
      const char* entry = abi::siteString(site, abi::printfSiteWords(site), 1);
      std::string body = std::string(fn) + ": debugPrintfEXT in " + shaderText(model, entry, pipeline) + ", " +
                         invocationText(model, id) + " | MessageID = 0x92394c89 | " + text;
      reportWithId(cb, Severity::Info, kPrintfMessageId, kPrintfMessageNumber, body);
    });
    if (uint64_t dropped = messages.droppedPrintfs()) {
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "%s: %llu more debugPrintfEXT messages were not delivered: a command delivers at most %u "
                    "(VKRT_PRINTF_LIMIT)",
                    fn, static_cast<unsigned long long>(dropped), exec::ShaderMessages::printfLimit());
      if (toStdout) {
        std::printf("vkrt: %s\n", buf);
      } else {
        reportWithId(cb, Severity::Info, kPrintfMessageId, kPrintfMessageNumber, buf);
      }
    }
    if (toStdout) std::fflush(stdout);
  }
  for (const exec::OutOfBoundsRecord& r : messages.outOfBoundsSites()) deliverOutOfBounds(cb, pipeline, fn, r, namer);
}

}  // namespace vkrt
