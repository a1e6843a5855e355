#pragma once
// Real-time pacing shared by the sources that replay or synthesise frames on the studio clock
// (file replay, the simulated camera).

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "core/clock.h"

namespace studio::capture {

// Waits, holding `lock` on the mutex that guards `stopping`, until CLOCK_REALTIME reaches
// `due_ns` (true), or `stopping` is set and `wake` notified, or the steady `deadline` passes
// (false in both cases).
bool wait_until_realtime(std::unique_lock<std::mutex>& lock, std::condition_variable& wake, const bool& stopping,
                         int64_t due_ns, std::chrono::steady_clock::time_point deadline);

}  // namespace studio::capture
