#include "runtime/notify.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace studio::runtime {
namespace {

// A datagram socket standing in for the service manager.
class FakeManager {
 public:
  explicit FakeManager(bool abstract) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    name_ = (abstract ? "@studio-notify-test-" : "/tmp/studio-notify-test-") + std::to_string(::getpid());
    std::memcpy(addr.sun_path, name_.c_str(), name_.size());
    if (abstract) addr.sun_path[0] = '\0';
    else ::unlink(name_.c_str());
    const socklen_t len = socklen_t(offsetof(sockaddr_un, sun_path) + name_.size());
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&addr), len), 0) << std::strerror(errno);
    ::setenv("NOTIFY_SOCKET", name_.c_str(), 1);
  }
  ~FakeManager() {
    ::unsetenv("NOTIFY_SOCKET");
    ::close(fd_);
    if (name_[0] == '/') ::unlink(name_.c_str());
  }
  std::string receive() {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 2000) != 1) return "<timeout>";
    char buf[256];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    return n < 0 ? "<error>" : std::string(buf, size_t(n));
  }

 private:
  int fd_ = -1;
  std::string name_;
};

TEST(Notify, SendsToPathSocket) {
  FakeManager manager(false);
  ASSERT_TRUE(notify("READY=1\nSTATUS=configured"));
  EXPECT_EQ(manager.receive(), "READY=1\nSTATUS=configured");
}

TEST(Notify, SendsToAbstractSocket) {
  FakeManager manager(true);
  ASSERT_TRUE(notify("STOPPING=1"));
  EXPECT_EQ(manager.receive(), "STOPPING=1");
}

TEST(Notify, NeverBlocksWhenTheReceiverStopsReading) {
  FakeManager manager(true);
  // Nobody reads: the datagram queue fills (a few hundred entries at most) and notify() must
  // report failure instead of blocking the service's main loop.
  int failures = 0;
  for (int i = 0; i < 5000 && failures == 0; ++i) failures += !notify("WATCHDOG=1");
  EXPECT_GT(failures, 0);
}

TEST(Notify, WithoutSocketReturnsFalse) {
  ::unsetenv("NOTIFY_SOCKET");
  EXPECT_FALSE(notify("READY=1"));
  ::setenv("NOTIFY_SOCKET", "/nonexistent/dir/sock", 1);
  EXPECT_FALSE(notify("READY=1"));
  ::unsetenv("NOTIFY_SOCKET");
}

TEST(Notify, WatchdogIntervalHonoursPid) {
  ::setenv("WATCHDOG_USEC", "3000000", 1);
  ::unsetenv("WATCHDOG_PID");
  ASSERT_TRUE(watchdog_interval().has_value());
  EXPECT_EQ(watchdog_interval()->count(), 3000000);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid() + 1).c_str(), 1);
  EXPECT_FALSE(watchdog_interval().has_value());
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  EXPECT_TRUE(watchdog_interval().has_value());
  ::setenv("WATCHDOG_USEC", "soon", 1);
  EXPECT_FALSE(watchdog_interval().has_value());
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
  EXPECT_FALSE(watchdog_interval().has_value());
}

}  // namespace
}  // namespace studio::runtime
