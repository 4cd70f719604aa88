// The CPU compiled shaders target. By default the host's (its name and every feature it has), so compiled code
// may use any instruction this CPU runs. A named x86-64 CPU (LLVM's names: "x86-64-v2", "x86-64-v3", "haswell",
// ...) limits code generation to that CPU's features: the tests run the compiler against such baselines on a CPU
// that has more, so that nothing they check depends on the development machine's instruction set.
#include "spirv/target.hpp"

#include <llvm/ADT/SmallVector.h>
#include <llvm/ADT/StringMap.h>
#include <llvm/Support/Host.h>
#include <llvm/Support/X86TargetParser.h>
#include <llvm/Support/raw_ostream.h>

#include <algorithm>
#include <mutex>
#include <vector>

#include "spirv/compiler.hpp"

namespace vkrt::spirv {
namespace {

struct Target {
  std::mutex mutex;
  std::string cpu;  // empty: the host CPU
  std::optional<llvm::orc::JITTargetMachineBuilder> machine;
  std::string error;
};

Target& target() {
  static Target* const t = new Target();  // never destroyed: compilations may run from static destructors
  return *t;
}

}  // namespace

bool setTargetCpu(std::string_view cpu, std::string* error) {
  std::string name(cpu == "native" ? std::string_view() : cpu);
  if (!name.empty()) {
    if (llvm::X86::parseArchX86(name, /*Only64Bit=*/true) == llvm::X86::CK_None) {
      if (error) *error = "\"" + name + "\" is not an x86-64 CPU LLVM knows (try x86-64-v2, x86-64-v3 or native)";
      return false;
    }
    // Code for a CPU with a feature this one lacks would fault on its first such instruction.
    llvm::SmallVector<llvm::StringRef, 64> needed;
    llvm::X86::getFeaturesForCPU(name, needed);
    llvm::StringMap<bool> host;
    if (llvm::sys::getHostCPUFeatures(host)) {
      std::string missing;
      for (llvm::StringRef f : needed) {
        auto it = host.find(f);
        if (it != host.end() && !it->second) missing += (missing.empty() ? "" : ", ") + f.str();
      }
      if (!missing.empty()) {
        if (error) *error = "this CPU lacks features of " + name + ": " + missing;
        return false;
      }
    }
  }
  Target& t = target();
  std::lock_guard lock(t.mutex);
  if (t.cpu != name) {
    t.cpu = name;
    t.machine.reset();
    t.error.clear();
  }
  return true;
}

std::string targetCpu() {
  Target& t = target();
  std::lock_guard lock(t.mutex);
  return t.cpu.empty() ? "native (" + llvm::sys::getHostCPUName().str() + ")" : t.cpu;
}

namespace detail {

std::string errText(llvm::Error e) {
  std::string s;
  llvm::raw_string_ostream os(s);
  os << e;
  return os.str();
}

std::optional<llvm::orc::JITTargetMachineBuilder> targetMachine(std::string* error) {
  Target& t = target();
  std::lock_guard lock(t.mutex);
  if (!t.machine && t.error.empty()) {
    std::optional<llvm::orc::JITTargetMachineBuilder> jtmb;
    if (t.cpu.empty()) {
      auto host = llvm::orc::JITTargetMachineBuilder::detectHost();
      if (host)
        jtmb = std::move(*host);
      else
        t.error = "LLVM: " + errText(host.takeError());
    } else {
      jtmb.emplace(llvm::Triple(llvm::sys::getProcessTriple()));
      jtmb->setCPU(t.cpu);  // no feature list: the CPU's own
    }
    if (jtmb) {
      jtmb->setCodeGenOptLevel(llvm::CodeGenOpt::Default);
      // Every function's frame size goes into a .stack_sizes section (frameBytes of RayStageInfo).
      jtmb->getOptions().EmitStackSizeSection = true;
      t.machine = std::move(jtmb);
    }
  }
  if (!t.machine) *error = t.error;
  return t.machine;
}

std::string targetKey() {
  static const std::string host = [] {
    std::string text = llvm::sys::getHostCPUName().str() + ":";
    llvm::StringMap<bool> features;
    if (llvm::sys::getHostCPUFeatures(features)) {
      std::vector<std::string> on;
      for (auto& f : features)
        if (f.second) on.push_back(f.first().str());
      std::sort(on.begin(), on.end());
      for (auto& f : on) text += f + ",";
    }
    return text;
  }();
  Target& t = target();
  std::lock_guard lock(t.mutex);
  return t.cpu.empty() ? "host " + host : "cpu " + t.cpu;
}

}  // namespace detail
}  // namespace vkrt::spirv
