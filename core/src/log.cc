#include "core/log.h"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <map>
#include <mutex>
#include <optional>

namespace studio::log {
namespace {

struct Registry {
  std::mutex mutex;
  Level fallback = Level::info;
  std::map<std::string, Level, std::less<>> levels;
};

std::optional<Level> parse_level(std::string_view s) {
  static constexpr std::string_view names[] = {"trace", "debug", "info", "warn", "error", "off"};
  for (int i = 0; i < 6; ++i)
    if (s == names[i]) return static_cast<Level>(i);
  return std::nullopt;
}

bool apply(Registry& r, std::string_view spec) {
  Level fallback = r.fallback;
  std::map<std::string, Level, std::less<>> levels;
  while (!spec.empty()) {
    const size_t comma = spec.find(',');
    std::string_view item = spec.substr(0, comma);
    spec = comma == std::string_view::npos ? std::string_view{} : spec.substr(comma + 1);
    if (item.empty()) continue;
    const size_t eq = item.find('=');
    if (eq == std::string_view::npos) {
      auto l = parse_level(item);
      if (!l) return false;
      fallback = *l;
    } else {
      auto l = parse_level(item.substr(eq + 1));
      if (!l || eq == 0) return false;
      levels.emplace(std::string(item.substr(0, eq)), *l);
    }
  }
  r.fallback = fallback;
  for (auto& [k, v] : levels) r.levels[k] = v;
  return true;
}

Registry& registry() {
  static Registry* r = [] {
    auto* reg = new Registry;  // never destroyed: logging stays usable during static destruction
    if (const char* env = std::getenv("STUDIO_LOG")) apply(*reg, env);
    return reg;
  }();
  return *r;
}

}  // namespace

void set_level(std::string_view category, Level level) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (category.empty())
    r.fallback = level;
  else
    r.levels[std::string(category)] = level;
}

Level level_for(std::string_view category) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  auto it = r.levels.find(category);
  return it == r.levels.end() ? r.fallback : it->second;
}

bool enabled(std::string_view category, Level level) {
  return level != Level::off && level >= level_for(category);
}

bool configure(std::string_view spec) {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  return apply(r, spec);
}

std::string_view level_name(Level level) {
  static constexpr std::string_view names[] = {"TRACE", "DEBUG", "INFO", "WARN", "ERROR", "OFF"};
  return names[static_cast<int>(level)];
}

Line::~Line() {
  using namespace std::chrono;
  const auto now = system_clock::now();
  const std::time_t t = system_clock::to_time_t(now);
  const long ms = duration_cast<milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%S", &tm);
  std::ostringstream line;
  line << stamp << '.' << (ms < 100 ? (ms < 10 ? "00" : "0") : "") << ms << "Z " << level_name(level_)
       << " [" << category_ << "] " << stream_.str() << '\n';
  const std::string text = line.str();
  // One write() per line keeps lines from concurrent threads whole.
  [[maybe_unused]] ssize_t n = ::write(STDERR_FILENO, text.data(), text.size());
}

}  // namespace studio::log
