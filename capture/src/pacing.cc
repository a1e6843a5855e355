#include "capture/pacing.h"

namespace studio::capture {


bool wait_until_realtime(std::unique_lock<std::mutex>& lock, std::condition_variable& wake, const bool& stopping,
                         int64_t due_ns, std::chrono::steady_clock::time_point deadline) {
  for (;;) {
    if (stopping) return false;
    const int64_t now = realtime_ns();
    if (now >= due_ns) return true;
    const auto until_due = std::chrono::steady_clock::now() + std::chrono::nanoseconds(due_ns - now);
    if (deadline <= until_due) {
      wake.wait_until(lock, deadline, [&] { return stopping; });
      return false;
    }
    wake.wait_until(lock, until_due, [&] { return stopping; });
  }
}

}  // namespace studio::capture
