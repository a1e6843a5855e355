#include "proc_stats.h"

#include <time.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

namespace studio::demo {

std::optional<ProcSample> read_proc(pid_t pid) {
  const std::string base = "/proc/" + std::to_string(pid);
  std::ifstream stat(base + "/stat");
  std::string line;
  if (!stat || !std::getline(stat, line)) return std::nullopt;
  // Field 2 (comm) may hold spaces: fields after the last ')' are positional. utime and stime
  // are fields 14 and 15, i.e. the 12th and 13th after the state field (3).
  const auto close = line.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream rest(line.substr(close + 2));
  std::string field;
  double utime = 0, stime = 0;
  for (int i = 3; i <= 15 && rest >> field; ++i) {
    if (i == 14) utime = std::stod(field);
    if (i == 15) stime = std::stod(field);
  }
  ProcSample s;
  s.cpu_s = (utime + stime) / double(sysconf(_SC_CLK_TCK));
  std::ifstream status(base + "/status");
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) {
      s.rss_mb = std::stod(line.substr(6)) / 1024.0;  // kB
      break;
    }
  }
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  s.taken_ns = int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
  return s;
}

double cpu_percent(const ProcSample& a, const ProcSample& b) {
  const double dt = double(b.taken_ns - a.taken_ns) * 1e-9;
  if (dt <= 0) return 0;
  return 100.0 * (b.cpu_s - a.cpu_s) / dt;
}

}  // namespace studio::demo
