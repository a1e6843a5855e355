#pragma once
// The studio's wall clock: CLOCK_REALTIME in nanoseconds, the clock of every sample's
// `capture_ns` (DESIGN §3, §5), so any service can compute end-to-end latency.

#include <chrono>
#include <cstdint>

namespace studio {

inline int64_t realtime_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace studio
