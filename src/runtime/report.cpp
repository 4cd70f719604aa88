#include "runtime/report.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "runtime/instance.hpp"

namespace vkrt {
namespace {

// VKRT_LOG: the lowest severity printed to stderr when an instance has no debug messenger.
Severity stderrThreshold(bool* silent) {
  const char* v = std::getenv("VKRT_LOG");
  *silent = false;
  if (!v || !*v || std::strcmp(v, "warning") == 0) return Severity::Warning;
  if (std::strcmp(v, "none") == 0) {
    *silent = true;
    return Severity::Error;
  }
  if (std::strcmp(v, "error") == 0) return Severity::Error;
  if (std::strcmp(v, "info") == 0) return Severity::Info;
  if (std::strcmp(v, "verbose") == 0) return Severity::Verbose;
  return Severity::Warning;
}

VkDebugUtilsMessageSeverityFlagBitsEXT toVk(Severity s) {
  switch (s) {
    case Severity::Verbose: return VK_DEBUG_UTILS_MESSAGE_SEVERITY_VERBOSE_BIT_EXT;
    case Severity::Info: return VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
    case Severity::Warning: return VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    case Severity::Error: break;
  }
  return VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
}

const char* severityWord(Severity s) {
  switch (s) {
    case Severity::Verbose: return "verbose";
    case Severity::Info: return "info";
    case Severity::Warning: return "warning";
    case Severity::Error: break;
  }
  return "error";
}

void deliver(const Object* about, Severity severity, const char* vuid, const char* idName, int32_t idNumber,
             const char* body) {
  std::string objectText;
  std::string name;
  if (about) {
    name = about->debugName();
    char buf[96];
    std::snprintf(buf, sizeof(buf), "%s 0x%llx", objectTypeName(about->objectType),
                  static_cast<unsigned long long>(about->handleValue()));
    objectText = buf;
    if (!name.empty()) objectText += " '" + name + "'";
  }
  std::string message = std::string("vkrt: ") + (vuid ? std::string("[ ") + vuid + " ] " : std::string()) +
                        (objectText.empty() ? "" : objectText + ": ") + body;

  const Instance* inst = about ? about->instance : nullptr;
  bool delivered = false;
  if (inst && inst->hasMessengers()) {
    VkDebugUtilsObjectNameInfoEXT object{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    object.objectType = about->objectType;
    object.objectHandle = about->handleValue();
    object.pObjectName = name.empty() ? nullptr : name.c_str();
    VkDebugUtilsMessengerCallbackDataEXT data{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
    data.pMessageIdName = idName;
    data.messageIdNumber = idNumber;
    data.pMessage = message.c_str();
    data.objectCount = 1;
    data.pObjects = &object;
    VkDebugUtilsMessageTypeFlagsEXT type =
        vuid ? VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT : VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    inst->dispatch(toVk(severity), type, data);
    delivered = true;
  }
  if (!delivered) {
    bool silent = false;
    Severity threshold = stderrThreshold(&silent);
    if (!silent && severity >= threshold) std::fprintf(stderr, "%s (%s)\n", message.c_str(), severityWord(severity));
  }
}

}  // namespace

void reportV(const Object* about, Severity severity, const char* vuid, const char* format, va_list args) {
  char body[2048];
  std::vsnprintf(body, sizeof(body), format, args);
  deliver(about, severity, vuid, vuid ? vuid : "vkrt", 0, body);
}

void reportText(const Object* about, Severity severity, const char* idName, const std::string& text) {
  deliver(about, severity, nullptr, idName, 0, text.c_str());
}

void reportWithId(const Object* about, Severity severity, const char* idName, int32_t idNumber,
                  const std::string& body) {
  deliver(about, severity, idName, idName, idNumber, body.c_str());
}

void report(const Object* about, Severity severity, const char* vuid, const char* format, ...) {
  va_list args;
  va_start(args, format);
  reportV(about, severity, vuid, format, args);
  va_end(args);
}

}  // namespace vkrt
