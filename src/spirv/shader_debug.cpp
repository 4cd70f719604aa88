#include "spirv/shader_debug.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <string_view>

namespace vkrt::spirv {

namespace {
std::atomic<uint32_t> checksOn{0};
}  // namespace

void setShaderChecks(uint32_t checks) { checksOn.store(checks, std::memory_order_relaxed); }
uint32_t shaderChecks() { return checksOn.load(std::memory_order_relaxed); }

bool parseShaderChecks(const char* text, uint32_t* checks) {
  uint32_t bits = 0;
  std::string_view rest = text ? text : "";
  while (!rest.empty()) {
    size_t comma = rest.find(',');
    std::string_view word = rest.substr(0, comma);
    if (word == "bda") {
      bits |= abi::kCheckDeviceAddress;
    } else if (word == "image") {
      bits |= abi::kCheckImage;
    } else if (word == "all") {
      bits |= abi::kCheckDeviceAddress | abi::kCheckImage;
    } else if (!word.empty() && word != "none") {
      return false;
    }
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
  }
  *checks = bits;
  return true;
}

namespace {

void putWord(std::string& s, uint32_t w) { s.append(reinterpret_cast<const char*>(&w), 4); }

void putString(std::string& s, const std::string& text) {
  s += text;
  s += '\0';
}

double asDouble(uint64_t bits) {
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

// One component as the conversion wants it. Floats travel as doubles; an integer printed by a float conversion
// is read as the float its bits make (the layer's words are bits), and a float printed by an integer conversion
// as its bits.
struct Component {
  const PrintfArg* arg;
  uint64_t bits;

  double asFloat() const {
    if (arg->kind == abi::kArgFloat) return asDouble(bits);
    if (arg->width == 64) return asDouble(bits);
    float f;
    uint32_t low = uint32_t(bits);
    std::memcpy(&f, &low, 4);
    return f;
  }
  uint64_t asInteger() const {
    if (arg->kind != abi::kArgFloat) return bits;
    if (arg->width == 64) return bits;
    float f = float(asDouble(bits));
    uint32_t w;
    std::memcpy(&w, &f, 4);
    return w;
  }
};

void appendConversion(std::string& out, const std::string& spec, char conv, bool wide, const Component& c) {
  char buf[512];
  std::string f = "%" + spec;
  switch (conv) {
    case 'd':
    case 'i': {
      uint64_t v = c.asInteger();
      if (wide) {
        std::snprintf(buf, sizeof buf, (f + "ll" + conv).c_str(), static_cast<long long>(v));
      } else {
        std::snprintf(buf, sizeof buf, (f + conv).c_str(), static_cast<int>(static_cast<int32_t>(uint32_t(v))));
      }
      break;
    }
    case 'u':
    case 'x':
    case 'X':
    case 'o': {
      uint64_t v = c.asInteger();
      if (wide) {
        std::snprintf(buf, sizeof buf, (f + "ll" + conv).c_str(), static_cast<unsigned long long>(v));
      } else {
        std::snprintf(buf, sizeof buf, (f + conv).c_str(), static_cast<unsigned>(uint32_t(v)));
      }
      break;
    }
    case 'c': std::snprintf(buf, sizeof buf, (f + conv).c_str(), static_cast<int>(uint8_t(c.asInteger()))); break;
    default: std::snprintf(buf, sizeof buf, (f + conv).c_str(), c.asFloat()); break;
  }
  out += buf;
}

bool isConversion(char c) { return c && std::strchr("diuxXocfFeEgGaA", c) != nullptr; }

}  // namespace

std::string printfSite(uint32_t model, const std::vector<PrintfArg>& args, const std::string& format,
                       const std::string& entryName) {
  std::string s;
  putWord(s, abi::kPrintfSiteTag);
  putWord(s, model);
  putWord(s, uint32_t(args.size()));
  for (const PrintfArg& a : args) putWord(s, a.kind | a.width << 8 | a.components << 16);
  putString(s, format);
  putString(s, entryName);
  return s;
}

std::string accessSite(const AccessSiteInfo& i) {
  std::string s;
  for (uint32_t w : {abi::kAccessSiteTag, i.model, i.kind, i.set, i.binding, i.bytes, i.wordOffset, i.line, i.column})
    putWord(s, w);
  putString(s, i.file);
  putString(s, i.entryName);
  putString(s, i.variable);
  return s;
}

AccessSiteInfo readAccessSite(const uint8_t* site) {
  AccessSiteInfo i;
  uint32_t* fields[] = {&i.model, &i.kind, &i.set, &i.binding, &i.bytes, &i.wordOffset, &i.line, &i.column};
  for (uint32_t k = 0; k < 8; ++k) *fields[k] = abi::siteWord(site, 1 + k);
  i.file = abi::siteString(site, abi::kAccessSiteWords, 0);
  i.entryName = abi::siteString(site, abi::kAccessSiteWords, 1);
  i.variable = abi::siteString(site, abi::kAccessSiteWords, 2);
  return i;
}

std::string formatPrintf(const uint8_t* site, const uint64_t* args) {
  const uint32_t argCount = abi::siteWord(site, 2);
  std::vector<PrintfArg> list(argCount);
  std::vector<const uint64_t*> values(argCount);
  for (uint32_t i = 0, at = 0; i < argCount; ++i) {
    uint32_t w = abi::siteWord(site, 3 + i);
    list[i] = {w & 0xff, w >> 8 & 0xff, w >> 16};
    values[i] = args + at;
    at += list[i].components;
  }
  const std::string format = abi::siteString(site, abi::printfSiteWords(site), 0);
  std::string out;
  uint32_t next = 0;  // the next argument
  for (size_t i = 0; i < format.size();) {
    if (format[i] != '%') {
      out += format[i++];
      continue;
    }
    if (i + 1 < format.size() && format[i + 1] == '%') {
      out += '%';
      i += 2;
      continue;
    }
    // %[flags][width][.precision][l][v<n>][l]<conversion>
    size_t j = i + 1;
    std::string spec;
    while (j < format.size() && std::strchr("-+ #0", format[j])) spec += format[j++];
    while (j < format.size() && format[j] >= '0' && format[j] <= '9') spec += format[j++];
    if (j < format.size() && format[j] == '.') {
      spec += format[j++];
      while (j < format.size() && format[j] >= '0' && format[j] <= '9') spec += format[j++];
    }
    bool wide = false;
    uint32_t vector = 0;
    if (j < format.size() && format[j] == 'l') wide = (++j, true);
    if (j + 1 < format.size() && format[j] == 'v' && format[j + 1] >= '2' && format[j + 1] <= '4') {
      vector = uint32_t(format[j + 1] - '0');
      j += 2;
    }
    if (j < format.size() && format[j] == 'l') wide = (++j, true);
    char conv = j < format.size() ? format[j] : 0;
    if (!isConversion(conv) || next >= argCount) {
      // Not a conversion this formatter knows, or no argument left: printed as written.
      out += format.substr(i, j - i + (conv ? 1 : 0));
      i = j + (conv ? 1 : 0);
      continue;
    }
    const PrintfArg& a = list[next];
    const uint64_t* v = values[next++];
    uint32_t n = vector ? std::min(vector, a.components) : 1;
    for (uint32_t k = 0; k < n; ++k) {
      if (k) out += ", ";
      appendConversion(out, spec, conv, wide, Component{&a, v[k]});
    }
    i = j + 1;
  }
  return out;
}

}  // namespace vkrt::spirv
