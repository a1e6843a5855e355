#include "runtime/signals.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <thread>

namespace studio::runtime {
namespace {

using namespace std::chrono_literals;

TEST(SignalWatcher, ReceivesSignalSentToProcess) {
  SignalWatcher watcher({SIGUSR1});
  EXPECT_FALSE(watcher.wait(0ms).has_value());
  // Delivered to the process from another thread: the signal is blocked there too, so it stays
  // pending and arrives through the signalfd rather than killing the process.
  std::thread sender([] { ::kill(::getpid(), SIGUSR1); });
  sender.join();
  auto got = watcher.wait(2000ms);
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(*got, SIGUSR1);
  EXPECT_FALSE(watcher.wait(0ms).has_value());
}

TEST(SignalWatcher, TimesOutWithoutSignal) {
  SignalWatcher watcher({SIGUSR2});
  EXPECT_FALSE(watcher.wait(20ms).has_value());
}

}  // namespace
}  // namespace studio::runtime
