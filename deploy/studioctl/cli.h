#pragma once
// studioctl's command-line plumbing: argument parsing shared by every verb, the DDS domain and
// profile chosen exactly as the services choose them (flag, else $STUDIO_DDS_DOMAIN /
// $CYCLONEDDS_URI; runtime/src/service.cc, wire::default_domain), and small parsers for values.

#include <chrono>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "wire/entity.h"

namespace studio::ctl {

struct Common {
  int domain = -1;         // --domain N; -1 = $STUDIO_DDS_DOMAIN, else Cyclone's default
  std::string dds_config;  // --dds-config FILE; empty = $CYCLONEDDS_URI
  bool json = false;       // --json
};

struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string, std::less<>> values;  // --flag VALUE / --flag=VALUE
  std::set<std::string, std::less<>> switches;             // --flag
  bool help = false;
  Common common;

  bool has(std::string_view flag) const { return switches.contains(flag) || values.contains(flag); }
  const std::string* value(std::string_view flag) const {
    auto it = values.find(flag);
    return it == values.end() ? nullptr : &it->second;
  }
};

// Parses argv (after the verb words). `valued` flags take a value, `switches` do not; the common
// flags (--domain, --dds-config, --json, --help/-h) are always accepted. Unknown flags and
// missing values are errors.
Expected<Args> parse_args(const std::vector<std::string>& argv,
                          std::initializer_list<std::string_view> valued,
                          std::initializer_list<std::string_view> switches = {});

Expected<wire::Participant> open_participant(const Common& common);

Expected<double> parse_seconds(std::string_view flag, const std::string& text, double min,
                               double max);
Expected<uint64_t> parse_count(std::string_view flag, const std::string& text);
Expected<double> parse_number(std::string_view what, const std::string& text);

// Reads `--flag` as seconds/count when present, else `fallback`.
Expected<double> seconds_flag(const Args& a, std::string_view flag, double fallback, double min,
                              double max);
Expected<uint64_t> count_flag(const Args& a, std::string_view flag, uint64_t fallback);

// "studioctl <what>: <message>" on stderr; returns `code`.
int complain(std::string_view what, std::string_view message, int code = 1);

std::chrono::nanoseconds to_ns(double seconds);
int64_t realtime_ns();

// Writes `line` + '\n' to stdout and flushes (output of a long-running command reaches a pipe
// at once).
void emit(std::string_view line);

}  // namespace studio::ctl
