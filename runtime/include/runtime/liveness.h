#pragma once
// Loop liveness: how the systemd watchdog sees a wedged ServiceLoop thread (issue 19 item 6).
//
// service_main pings WATCHDOG=1 from the main thread; on its own that proves only that the main
// thread runs, not that the node works. So every ServiceLoop of the service attaches a Beat here
// while it runs and stamps it each time its loop thread comes round (a turn: a wake for data, a
// timer, wake(), or at the latest every turn_period() when idle). service_main asks stalled()
// before each ping: while some attached loop has not turned for longer than the bound, it sends
// no ping (systemd's WatchdogSec then kills and restarts the service), reports the service
// DEGRADED and says which loop, in STATUS= and the log.
//
// Contract
// - bound > 0. A healthy idle loop turns every turn_period() = bound / 4, so only a loop stuck
//   in one turn for longer than the bound (a handler that never returns, a deadlock, a busy
//   loop) counts as stalled; a turn that legitimately takes longer than the bound also does.
// - attach()/detach()/stalled() are thread-safe; Beat::turn() is lock-free (one atomic store).
// - A service with no attached loop is never stalled (its main loop alone decides).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace studio::runtime {

using SteadyClock = std::chrono::steady_clock;

class Liveness {
 public:
  // One monitored loop thread.
  class Beat {
   public:
    Beat(std::string name, SteadyClock::time_point now) : name_(std::move(name)) { turn(now); }
    void turn(SteadyClock::time_point now) {
      last_.store(now.time_since_epoch().count(), std::memory_order_relaxed);
    }
    SteadyClock::time_point last() const {
      return SteadyClock::time_point(SteadyClock::duration(last_.load(std::memory_order_relaxed)));
    }
    const std::string& name() const { return name_; }

   private:
    std::string name_;
    std::atomic<SteadyClock::rep> last_{0};
  };
  // The loop silent the longest, when that is longer than the bound.
  struct Stall {
    std::string name;
    SteadyClock::duration silent;
  };

  explicit Liveness(SteadyClock::duration bound) : bound_(bound) {}
  SteadyClock::duration bound() const { return bound_; }
  SteadyClock::duration turn_period() const { return bound_ / 4; }

  std::shared_ptr<Beat> attach(std::string name);
  void detach(const std::shared_ptr<Beat>& beat);
  std::optional<Stall> stalled(SteadyClock::time_point now) const;

 private:
  SteadyClock::duration bound_;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<Beat>> beats_;
};

}  // namespace studio::runtime
