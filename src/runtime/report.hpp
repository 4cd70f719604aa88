// The one funnel for everything vkrt reports: Valid Usage violations, bad input, and notes.
//
// A report names the object it is about (type, handle, debug name), the rule (a VUID where one applies)
// and the values involved. It goes to every VK_EXT_debug_utils messenger of the object's instance whose
// severity and type filters accept it. When the instance has no messenger, it goes to stderr according
// to VKRT_LOG (see the README): "none", "error", "warning" (the default) or "info".
#pragma once

#include <cstdarg>
#include <cstdint>
#include <string>

#include "runtime/object.hpp"

namespace vkrt {

enum class Severity { Verbose, Info, Warning, Error };

// `about` may be null (for reports before any instance exists). `vuid` may be null when no VUID applies.
void report(const Object* about, Severity severity, const char* vuid, const char* format, ...)
    __attribute__((format(printf, 4, 5)));

// The same with the arguments as a va_list.
void reportV(const Object* about, Severity severity, const char* vuid, const char* format, va_list args);

// A report of any length that is no rule's (no VUID), under the message id name `idName` (a ray tree).
void reportText(const Object* about, Severity severity, const char* idName, const std::string& text);

// A report whose message id is not a VUID (shader debugging, runtime/shader_messages.cpp): `idName` goes to
// pMessageIdName and into the text like a VUID, `idNumber` to messageIdNumber; the type is VALIDATION.
void reportWithId(const Object* about, Severity severity, const char* idName, int32_t idNumber,
                  const std::string& body);

}  // namespace vkrt
