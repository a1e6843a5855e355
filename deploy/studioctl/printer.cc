#include "studioctl/printer.h"

#include <charconv>
#include <cmath>
#include <cstring>

namespace studio::ctl {
namespace {

constexpr std::size_t kTextInline = 12;  // numeric arrays up to this length are printed in full
constexpr std::size_t kTextShown = 8;    // longer ones: this many, then "... (N values)"

template <class T>
std::string shortest(T v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace

std::string_view Printer::bounded(const char* text, std::size_t capacity) {
  return {text, strnlen(text, capacity)};
}

void Printer::append_json_string(std::string& out, std::string_view s) {
  out += '"';
  for (unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += char(c);
        }
    }
  }
  out += '"';
}

void Printer::begin_object() {
  if (json()) {
    out_ += '{';
  } else if (!ctx_.empty()) {
    if (ctx_.back() == Ctx::object) out_ += '\n';
    indent_ += 2;
  }
  ctx_.push_back(Ctx::object);
  first_.push_back(true);
}

void Printer::end_object() {
  ctx_.pop_back();
  first_.pop_back();
  if (json())
    out_ += '}';
  else if (!ctx_.empty())
    indent_ -= 2;
}

void Printer::key(std::string_view name) {
  if (json()) {
    if (!first_.back()) out_ += ',';
    first_.back() = false;
    append_json_string(out_, name);
    out_ += ':';
    return;
  }
  out_.append(std::size_t(indent_ - (dash_ ? 2 : 0)), ' ');
  if (dash_) out_ += "- ";
  dash_ = false;
  out_ += name;
  out_ += ':';
}

void Printer::scalar(std::string_view json_text, std::string_view text) {
  if (json()) {
    out_ += json_text;
  } else if (!ctx_.empty() && ctx_.back() == Ctx::scalar_array) {
    out_ += text;
  } else {
    out_ += ' ';
    out_ += text;
    out_ += '\n';
  }
}

void Printer::number(double v) {
  const std::string s = shortest(v);
  scalar(std::isfinite(v) ? std::string_view(s) : "null", s);
}
void Printer::number(float v) {
  const std::string s = shortest(v);
  scalar(std::isfinite(v) ? std::string_view(s) : "null", s);
}
void Printer::number(bool v) { scalar(v ? "true" : "false", v ? "true" : "false"); }
void Printer::number(int64_t v) {
  const std::string s = shortest(v);
  scalar(s, s);
}
void Printer::number(uint64_t v) {
  const std::string s = shortest(v);
  scalar(s, s);
}
void Printer::null() { scalar("null", "null"); }

void Printer::string(const char* text, std::size_t capacity) {
  const std::string_view s = bounded(text, capacity);
  std::string quoted;
  append_json_string(quoted, s);
  // Text: as is, quoted when empty or when it would not read as one word.
  const bool plain = !s.empty() && s.find_first_of("\n\r\t\"") == std::string_view::npos &&
                     s.front() != ' ' && s.back() != ' ';
  scalar(quoted, plain ? s : std::string_view(quoted));
}

void Printer::enumeration(const char* name, int64_t value) {
  if (name != nullptr) {
    std::string quoted;
    append_json_string(quoted, name);
    scalar(quoted, name);
  } else {
    const std::string n = shortest(value);
    scalar(n, "<invalid " + n + ">");
  }
}

std::size_t Printer::begin_array(std::size_t count, bool structured, bool bulky) {
  first_.push_back(true);
  if (json()) {
    out_ += '[';
    ctx_.push_back(structured ? Ctx::struct_array : Ctx::scalar_array);
    return count;
  }
  if (structured) {
    ctx_.push_back(Ctx::struct_array);
    if (count == 0) {
      out_ += " []\n";
    } else {
      out_ += '\n';
      indent_ += 2;
    }
    return count;
  }
  if (bulky) {
    ctx_.push_back(Ctx::bytes);
    out_ += " <" + std::to_string(count) + " bytes>\n";
    return 0;
  }
  ctx_.push_back(Ctx::scalar_array);
  out_ += " [";
  return count <= kTextInline ? count : kTextShown;
}

void Printer::element() {
  if (json()) {
    if (!first_.back()) out_ += ',';
  } else if (ctx_.back() == Ctx::scalar_array) {
    if (!first_.back()) out_ += ", ";
  } else {
    dash_ = true;
  }
  first_.back() = false;
}

void Printer::end_array(std::size_t count, std::size_t shown) {
  const Ctx ctx = ctx_.back();
  ctx_.pop_back();
  first_.pop_back();
  if (json()) {
    out_ += ']';
    return;
  }
  if (ctx == Ctx::struct_array) {
    if (count > 0) indent_ -= 2;
    return;
  }
  if (ctx == Ctx::bytes) return;  // "<N bytes>" printed by begin_array
  if (shown < count) out_ += (shown ? ", ... (" : "... (") + std::to_string(count) + " values)";
  out_ += "]\n";
}

std::string Printer::take() {
  std::string s = std::move(out_);
  out_.clear();
  ctx_.clear();
  first_.clear();
  indent_ = 0;
  dash_ = false;
  return s;
}

}  // namespace studio::ctl
