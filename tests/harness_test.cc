// The harness itself: readiness over NOTIFY_SOCKET, log capture, exit codes, SIGTERM then
// SIGKILL, and the watchdog.

#include <gtest/gtest.h>

#include <fstream>
#include <thread>

#include "harness/fixture.h"

namespace studio::testing {
namespace {

using namespace std::chrono_literals;

Process sh(const std::filesystem::path& dir, const std::string& name, const std::string& script) {
  auto p = Process::start(
      {.name = name, .binary = "/bin/sh", .args = {"-c", script}, .env = {}, .dir = dir});
  if (!p) throw std::runtime_error(p.error().message);
  return std::move(*p);
}

class HarnessTest : public ProcessTest {};

TEST_F(HarnessTest, ReadyArrivesOverTheNotifySocketAndLogsAreCaptured) {
  // The wire peer uses runtime::notify, the code path of every service.
  Process& peer = spawn("peer", "tests/wire_peer", {"bench-echo"});
  ASSERT_TRUE(peer.wait_ready(15s));
  EXPECT_TRUE(peer.running());
  EXPECT_EQ(peer.stop(), 0);
  Process p = sh(dir_, "echo", "echo hello-from-child; echo to-stderr >&2");
  EXPECT_EQ(p.wait_exit(5s), 0);
  EXPECT_NE(p.log().find("hello-from-child"), std::string::npos);
  EXPECT_NE(p.log().find("to-stderr"), std::string::npos);
}

TEST_F(HarnessTest, ChildSeesTheTestDomain) {
  Process p =
      Process::start({.name = "env",
                      .binary = "/bin/sh",
                      .args = {"-c", "echo $STUDIO_DDS_DOMAIN $STUDIO_DDS_TAG $CYCLONEDDS_URI"},
                      .env = dds_.env(),
                      .dir = dir_})
          .value();
  ASSERT_EQ(p.wait_exit(5s), 0);
  EXPECT_NE(p.log().find(std::to_string(dds_.domain_id) + " " + dds_.tag), std::string::npos)
      << p.log();
  EXPECT_NE(p.log().find("deploy/dds/loopback.xml"), std::string::npos);
}

TEST_F(HarnessTest, WaitReadyFailsFastWhenTheProcessExits) {
  Process p = sh(dir_, "quitter", "exit 3");
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(p.wait_ready(10s));
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 5s);
  EXPECT_EQ(p.wait_exit(1s), 3);
}

TEST_F(HarnessTest, WaitReadyTimesOutWithoutReady) {
  Process p = sh(dir_, "silent", "sleep 20");
  EXPECT_FALSE(p.wait_ready(300ms));
  EXPECT_EQ(p.stop(), -SIGTERM);
}

TEST_F(HarnessTest, StopEscalatesToSigkillAndTakesTheWholeGroup) {
  // The shell ignores SIGTERM and has a child of its own in the same group.
  Process p = sh(dir_, "stubborn", "trap '' TERM; sleep 30 & echo child=$!; wait; sleep 30");
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(p.stop(300ms), -SIGKILL);
  const auto log = p.log();
  const auto at = log.find("child=");
  ASSERT_NE(at, std::string::npos);
  const pid_t child = std::stoi(log.substr(at + 6));
  // Dead means gone or a zombie waiting for its new parent (init) to reap it.
  auto alive = [](pid_t pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string pid_field, comm, state;
    return bool(stat >> pid_field >> comm >> state) && state != "Z";
  };
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  while (alive(child) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(10ms);
  EXPECT_FALSE(alive(child)) << "grandchild survived";
}

TEST(WatchdogDeathTest, KillsTheTestWhenItOverruns) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        Watchdog dog(std::chrono::seconds(1));
        std::this_thread::sleep_for(10s);
      },
      ::testing::ExitedWithCode(124), "watchdog: test exceeded 1 s");
}

}  // namespace
}  // namespace studio::testing
