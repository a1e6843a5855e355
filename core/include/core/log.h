#pragma once
// A small logging facility with per-component categories and levels.
//
//   STUDIO_LOG(info, "hull") << "cut " << n << " columns";
//
// Levels: trace < debug < info < warn < error < off. The threshold per category comes from
// set_level() or from the environment variable STUDIO_LOG, e.g. "info" or "warn,hull=debug,dds=trace"
// (read once, at first use). Lines go to stderr as "<iso time> <level> [<category>] message";
// a line is written with one write() so lines from threads do not interleave. The stream
// expression is not evaluated when the level is disabled.

#include <sstream>
#include <string>
#include <string_view>

namespace studio::log {

enum class Level { trace = 0, debug, info, warn, error, off };

// Threshold for a category ("" = default for every category without its own).
void set_level(std::string_view category, Level level);
Level level_for(std::string_view category);
bool enabled(std::string_view category, Level level);
// Parses "info,hull=debug" and applies it: the default level and the named categories' levels;
// categories not named keep theirs (so a service's `log:` key adds to $STUDIO_LOG). Returns false
// (and changes nothing) on a malformed spec.
bool configure(std::string_view spec);
std::string_view level_name(Level level);

class Line {
 public:
  Line(Level level, std::string_view category) : level_(level), category_(category) {}
  Line(const Line&) = delete;
  Line& operator=(const Line&) = delete;
  ~Line();
  template <class T>
  Line& operator<<(const T& value) {
    stream_ << value;
    return *this;
  }

 private:
  Level level_;
  std::string_view category_;
  std::ostringstream stream_;
};

// Turns `Line(...) << a << b` into a void expression for the conditional in STUDIO_LOG
// ('&' binds looser than '<<').
struct Voidify {
  void operator&(const Line&) const {}
};

}  // namespace studio::log

// STUDIO_LOG(warn, "hull") << "frame " << n << ": " << message;
// The arguments are not evaluated when the level is off. An expression, not an if/else, so it is
// safe as the body of an unbraced if.
#define STUDIO_LOG(level, category)                                             \
  !::studio::log::enabled((category), ::studio::log::Level::level)              \
      ? (void)0                                                                 \
      : ::studio::log::Voidify() & ::studio::log::Line(::studio::log::Level::level, (category))
