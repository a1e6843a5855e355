#include "studioctl/cli.h"

#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace studio::ctl {

Expected<Args> parse_args(const std::vector<std::string>& argv,
                          std::initializer_list<std::string_view> valued,
                          std::initializer_list<std::string_view> switches) {
  Args a;
  auto is_valued = [&](std::string_view f) {
    if (f == "--domain" || f == "--dds-config") return true;
    for (auto v : valued)
      if (v == f) return true;
    return false;
  };
  auto is_switch = [&](std::string_view f) {
    if (f == "--json" || f == "--help" || f == "-h") return true;
    for (auto s : switches)
      if (s == f) return true;
    return false;
  };
  for (std::size_t i = 0; i < argv.size(); ++i) {
    std::string arg = argv[i];
    if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9') || arg[1] == '.') {
      a.positional.push_back(arg);  // words and negative numbers (camera set ... -3)
      continue;
    }
    std::string value;
    bool inline_value = false;
    if (auto eq = arg.find('='); eq != std::string::npos && arg.starts_with("--")) {
      value = arg.substr(eq + 1);
      arg = arg.substr(0, eq);
      inline_value = true;
    }
    if (is_valued(arg)) {
      if (!inline_value) {
        if (i + 1 == argv.size()) return fail(arg + " needs a value (see --help)");
        value = argv[++i];
      }
      a.values[arg] = value;
    } else if (is_switch(arg) && !inline_value) {
      a.switches.insert(arg);
    } else {
      return fail("unknown option '" + argv[i] + "' (see --help)");
    }
  }
  a.help = a.switches.contains("--help") || a.switches.contains("-h");
  a.common.json = a.switches.contains("--json");
  if (auto* d = a.value("--domain")) {
    int v = -1;
    auto r = std::from_chars(d->data(), d->data() + d->size(), v);
    if (r.ec != std::errc() || r.ptr != d->data() + d->size() || v < 0 || v > 232)
      return fail("--domain: expected a DDS domain id in 0..232, got '" + *d + "'");
    a.common.domain = v;
  }
  if (auto* c = a.value("--dds-config")) {
    if (::access(c->c_str(), R_OK) != 0)
      return fail("--dds-config: cannot read '" + *c + "': " + std::strerror(errno));
    a.common.dds_config = "file://" + *c;
  }
  return a;
}

Expected<wire::Participant> open_participant(const Common& common) {
  return wire::Participant::create(
      common.domain >= 0 ? dds_domainid_t(common.domain) : wire::default_domain(),
      common.dds_config);
}

Expected<double> parse_number(std::string_view what, const std::string& text) {
  double v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() ||
      !std::isfinite(v))
    return fail(std::string(what) + ": expected a number, got '" + text + "'");
  return v;
}

Expected<double> parse_seconds(std::string_view flag, const std::string& text, double min,
                               double max) {
  auto v = parse_number(flag, text);
  if (!v) return v;
  if (*v < min || *v > max)
    return fail(std::string(flag) + ": expected seconds in " + std::to_string(min).substr(0, 5) +
                ".." + std::to_string(max).substr(0, 7) + ", got '" + text + "'");
  return v;
}

Expected<uint64_t> parse_count(std::string_view flag, const std::string& text) {
  uint64_t v = 0;
  auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size())
    return fail(std::string(flag) + ": expected a non-negative integer, got '" + text + "'");
  return v;
}

Expected<double> seconds_flag(const Args& a, std::string_view flag, double fallback, double min,
                              double max) {
  const std::string* v = a.value(flag);
  return v ? parse_seconds(flag, *v, min, max) : Expected<double>(fallback);
}

Expected<uint64_t> count_flag(const Args& a, std::string_view flag, uint64_t fallback) {
  const std::string* v = a.value(flag);
  return v ? parse_count(flag, *v) : Expected<uint64_t>(fallback);
}

int complain(std::string_view what, std::string_view message, int code) {
  std::fprintf(stderr, "studioctl %.*s: %.*s\n", int(what.size()), what.data(), int(message.size()),
               message.data());
  return code;
}

std::chrono::nanoseconds to_ns(double seconds) {
  return std::chrono::nanoseconds(int64_t(seconds * 1e9));
}

int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void emit(std::string_view line) {
  std::fwrite(line.data(), 1, line.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

}  // namespace studio::ctl
