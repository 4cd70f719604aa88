// The examples' error exit (example_vk.hpp, gltf_util.hpp): a message with the program's name, exit status 1.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace example {

// The program's name, for messages (main sets it).
inline const char* gProgram = "example";

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "%s: %s\n", gProgram, what.c_str());
  std::exit(1);
}

}  // namespace example
