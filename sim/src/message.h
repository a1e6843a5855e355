#pragma once
// cat("x = ", x, " m"): builds a one-line error message (g++ 12 has no std::format).
#include <sstream>
#include <string>

namespace studio::sim::detail {
template <class... A>
std::string cat(const A&... parts) {
  std::ostringstream s;
  (s << ... << parts);
  return s.str();
}
}  // namespace studio::sim::detail
