#pragma once
// Shutdown and reload signals without flags set in handlers: the signals are blocked in every
// thread and read from a signalfd, so the main loop can poll them next to its other file
// descriptors (DESIGN §2 rule 4).
//
// Construct the SignalWatcher in main() BEFORE starting any thread (threads inherit the
// blocked mask; a thread started earlier could still receive the signal asynchronously).

#include <chrono>
#include <initializer_list>
#include <optional>

namespace studio::runtime {

class SignalWatcher {
 public:
  // Blocks and watches SIGINT, SIGTERM and SIGHUP by default.
  SignalWatcher();
  explicit SignalWatcher(std::initializer_list<int> signals);
  ~SignalWatcher();
  SignalWatcher(const SignalWatcher&) = delete;
  SignalWatcher& operator=(const SignalWatcher&) = delete;

  // Readable when a signal is pending; for poll()/epoll.
  int fd() const { return fd_; }
  // Waits up to `timeout` (negative: forever) and returns the signal received, if any.
  std::optional<int> wait(std::chrono::milliseconds timeout);

 private:
  int fd_ = -1;
};

}  // namespace studio::runtime
