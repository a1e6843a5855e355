#pragma once
// printf-style one-line messages (g++ 12 has no <format>). Private to the projector library.

#include <cstdio>
#include <string>

namespace studio::projector {

template <class... Args>
std::string text(const char* pattern, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof buffer, pattern, args...);
  return buffer;
}

}  // namespace studio::projector
