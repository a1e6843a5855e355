#pragma once
// Real-time pacing shared by the sources that replay or synthesise frames on the studio clock
// (file replay, the simulated camera).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace studio::capture {

// CLOCK_REALTIME in nanoseconds (the clock of capture_ns, DESIGN §5).
int64_t realtime_ns();

// Waits, holding `lock` on the mutex that guards `stopping`, until CLOCK_REALTIME reaches
// `due_ns` (true), or `stopping` is set and `wake` notified, or the steady `deadline` passes
// (false in both cases).
bool wait_until_realtime(std::unique_lock<std::mutex>& lock, std::condition_variable& wake, const bool& stopping,
                         int64_t due_ns, std::chrono::steady_clock::time_point deadline);

}  // namespace studio::capture
