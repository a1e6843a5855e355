#pragma once
// CPU time and resident memory of a process on this machine, from /proc/<pid>/stat and
// /proc/<pid>/status (Linux). The demo runs every service on one host, so the pid a service
// reports in studio/service/status names a process here.

#include <sys/types.h>

#include <cstdint>
#include <optional>

namespace studio::demo {

struct ProcSample {
  double cpu_s = 0;      // user + system CPU seconds since the process started
  double rss_mb = 0;     // VmRSS, MiB
  int64_t taken_ns = 0;  // CLOCK_MONOTONIC when read
};

// nullopt when the process does not exist (or /proc is unreadable).
std::optional<ProcSample> read_proc(pid_t pid);

// CPU % of one core between two samples of the same process (100 = one core busy).
double cpu_percent(const ProcSample& a, const ProcSample& b);

}  // namespace studio::demo
