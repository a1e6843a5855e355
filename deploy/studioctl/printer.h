#pragma once
// Printer: the output of one sample (or one record of any studioctl command), as JSON (one
// compact object per line, the IDL's member names, arrays as arrays, enums by name, non-finite
// numbers as null) or as readable text ("name: value" lines, nested structs indented, lists of
// structs with "- ", long numeric arrays summarised, byte sequences as "<N bytes>").
//
// The generated printers (gen_printers.py → studioctl_types.cc) drive it member by member:
//   p.begin_object(); p.key("frame"); p.number(s.frame); ... p.end_object();
// Arrays: n = p.begin_array(count, structured, bulky); for i < n: { p.element(); value } ;
//         p.end_array(count, n). In JSON every element is printed.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace studio::ctl {

class Printer {
 public:
  enum class Mode { json, text };
  explicit Printer(Mode mode) : mode_(mode) {}
  bool json() const { return mode_ == Mode::json; }

  void begin_object();
  void end_object();
  void key(std::string_view name);

  void number(double v);
  void number(float v);
  void number(bool v);
  void number(int64_t v);
  void number(uint64_t v);
  template <class T>
  requires(std::is_integral_v<T> && !std::is_same_v<T, bool> && !std::is_same_v<T, int64_t> &&
           !std::is_same_v<T, uint64_t>) void number(T v) {
    if constexpr (std::is_signed_v<T>)
      number(int64_t(v));
    else
      number(uint64_t(v));
  }
  void string(const char* text, std::size_t capacity);
  void string(std::string_view text) { string(text.data(), text.size()); }
  // name == nullptr: a value outside the enum (printed as its number, flagged in text).
  void enumeration(const char* name, int64_t value);
  void null();

  std::size_t begin_array(std::size_t count, bool structured, bool bulky = false);
  void element();
  void end_array(std::size_t count, std::size_t shown);

  // The text so far (JSON: one line without the newline), and reset.
  std::string take();

  // A bounded IDL string: the bytes up to the first NUL or `capacity`.
  static std::string_view bounded(const char* text, std::size_t capacity);
  static void append_json_string(std::string& out, std::string_view s);

 private:
  enum class Ctx { object, scalar_array, struct_array, bytes };
  void scalar(std::string_view json_text, std::string_view text);

  Mode mode_;
  std::string out_;
  std::vector<Ctx> ctx_;
  std::vector<bool> first_;
  int indent_ = 0;
  bool dash_ = false;
};

}  // namespace studio::ctl
