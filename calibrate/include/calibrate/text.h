#pragma once
// format("{} of {:.3f} px", n, x): a small subset of std::format (which g++ 12 lacks).
// Specs: {} {:.Nf} {:.Ng} {:Nd} {:0Nd} {:0Nx}; {{ and }} are literal braces. Extra {} without an
// argument are kept verbatim (a programming error, never a crash).

#include <iomanip>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace studio::calibrate {
namespace text_detail {

template <class T>
void put(std::ostringstream& out, std::string_view spec, const T& value) {
  std::ostringstream s;
  size_t i = 0;
  if (i < spec.size() && spec[i] == '0') {
    s << std::setfill('0');
    ++i;
  }
  int width = 0;
  while (i < spec.size() && spec[i] >= '0' && spec[i] <= '9') width = width * 10 + (spec[i++] - '0');
  if (width > 0) s << std::setw(width);
  if (i < spec.size() && spec[i] == '.') {
    int precision = 0;
    ++i;
    while (i < spec.size() && spec[i] >= '0' && spec[i] <= '9')
      precision = precision * 10 + (spec[i++] - '0');
    s << std::setprecision(precision);
  }
  if (i < spec.size()) {
    if (spec[i] == 'f') s << std::fixed;
    if (spec[i] == 'x') s << std::hex;
  }
  s << value;
  out << s.str();
}

inline void emit(std::ostringstream& out, std::string_view fmt, size_t& pos) {
  // Copies literal text up to the next unescaped '{' (left at pos) or the end.
  while (pos < fmt.size()) {
    if (fmt[pos] == '{' && pos + 1 < fmt.size() && fmt[pos + 1] == '{') {
      out << '{';
      pos += 2;
    } else if (fmt[pos] == '}' && pos + 1 < fmt.size() && fmt[pos + 1] == '}') {
      out << '}';
      pos += 2;
    } else if (fmt[pos] == '{') {
      return;
    } else {
      out << fmt[pos++];
    }
  }
}

}  // namespace text_detail

template <class... Args>
std::string format(std::string_view fmt, const Args&... args) {
  std::ostringstream out;
  size_t pos = 0;
  auto one = [&](const auto& value) {
    text_detail::emit(out, fmt, pos);
    if (pos >= fmt.size()) return;
    const size_t close = fmt.find('}', pos);
    if (close == std::string_view::npos) {
      out << fmt.substr(pos);
      pos = fmt.size();
      return;
    }
    std::string_view spec = fmt.substr(pos + 1, close - pos - 1);
    if (!spec.empty() && spec[0] == ':') spec.remove_prefix(1);
    text_detail::put(out, spec, value);
    pos = close + 1;
  };
  (one(args), ...);
  while (pos < fmt.size()) {
    text_detail::emit(out, fmt, pos);
    if (pos < fmt.size()) out << fmt[pos++];
  }
  return out.str();
}

}  // namespace studio::calibrate
