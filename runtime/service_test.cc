// service_main as a real process: config errors, READY/WATCHDOG/STOPPING notifications, status
// samples over DDS, clean exit on SIGTERM.
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

#include "harness/fixture.h"
#include "runtime/status_publisher.h"
#include "wire/endpoint.h"

namespace studio::runtime {
namespace {

using namespace std::chrono_literals;

class ServiceTest : public testing::ProcessTest {
 protected:
  std::string write_config(const std::string& text) {
    const auto path = dir_ / "probe.yaml";
    std::ofstream(path) << text;
    return path.string();
  }
};

TEST_F(ServiceTest, HelpListsCommonKeysAndExitsZero) {
  auto& p = spawn("probe", "runtime/probe_service", {"--help"});
  ASSERT_EQ(p.wait_exit(10s), 0);
  EXPECT_NE(p.log().find("status_period"), std::string::npos) << p.log();
  EXPECT_NE(p.log().find("degraded: BOOL"), std::string::npos) << p.log();
}

TEST_F(ServiceTest, ConfigErrorsAreOneLineAndNonZero) {
  struct Case {
    std::string yaml, expect;
  } cases[] = {
      {"instance: a\nbogus: 3\n", "probe.yaml:2: bogus: unknown key"},
      {"status_period: 0.001\n", "probe.yaml:1: status_period: expected seconds in 0.1..60"},
      {"degraded: maybe\n", "probe.yaml:1: degraded"},
      {"instance: [a\n", "probe.yaml"},
      {"log: loud\n", "malformed log spec"},
  };
  for (const auto& c : cases) {
    const std::string path = write_config(c.yaml);
    auto& p = spawn("probe", "runtime/probe_service", {"--config", path});
    auto rc = p.wait_exit(10s);
    ASSERT_TRUE(rc.has_value());
    EXPECT_EQ(*rc, 1) << c.yaml;
    const std::string log = p.log();
    EXPECT_NE(log.find(c.expect), std::string::npos) << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << log;
  }
  auto& missing = spawn("probe", "runtime/probe_service", {"--config", (dir_ / "nope.yaml").string()});
  EXPECT_EQ(missing.wait_exit(10s), 1);
  auto& noargs = spawn("probe", "runtime/probe_service", {});
  EXPECT_EQ(noargs.wait_exit(10s), 2);
  auto& nofile = spawn("probe", "runtime/probe_service", {"--config"});
  EXPECT_EQ(nofile.wait_exit(10s), 2);
  EXPECT_NE(nofile.log().find("--config needs a FILE"), std::string::npos) << nofile.log();
}

TEST_F(ServiceTest, LifecycleNotifiesAndPublishesStatus) {
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto reader = wire::Reader<studio_ServiceStatus>::create(participant, topic).value();

  const std::string path = write_config("instance: probe-1\nstatus_period: 0.2\n");
  auto& p = spawn("probe", "runtime/probe_service", {"--config", path});
  ASSERT_TRUE(p.wait_ready(20s)) << p.log();

  // Status samples arrive with the identity, state and counters of the service.
  bool running_seen = false;
  double ticks = 0;
  const auto deadline = std::chrono::steady_clock::now() + 15s;
  while (std::chrono::steady_clock::now() < deadline && !(running_seen && ticks > 0)) {
    for (auto& s : reader.take()) {
      if (!s.meta.valid_data) continue;
      EXPECT_STREQ(s.data->service, "probe");
      EXPECT_STREQ(s.data->instance, "probe-1");
      EXPECT_EQ(s.data->pid, p.pid());
      if (s.data->state == studio_SERVICE_RUNNING) running_seen = true;
      for (const auto& c : wire::view(s.data->counters))
        if (std::string(c.name) == "ticks") ticks = c.value;
    }
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_TRUE(running_seen);
  EXPECT_GT(ticks, 0);

  ASSERT_EQ(::kill(p.pid(), SIGTERM), 0);
  bool stopping = false;
  while (auto n = p.next_notification(5s)) {
    if (n->find("STOPPING=1") != std::string::npos) {
      stopping = true;
      break;
    }
  }
  EXPECT_TRUE(stopping);
  EXPECT_EQ(p.wait_exit(10s), 0) << p.log();
}

// A service killed without a word (kill -9: no dispose, no unregister) disappears from every
// status reader when its liveliness lease (3 s, wire QoS table) runs out: the reader's writer
// loses liveliness and the service's instance turns not-alive.
// A gauge that is not finite (an unbounded allowance) is left out of the status; the status
// still reaches a validated reader with every other value (before, the reader refused the whole
// sample and the service looked silent). Control: the finite value arrives.
TEST_F(ServiceTest, NonFiniteGaugeIsLeftOutNotTheWholeStatus) {
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto reader = wire::Reader<studio_ServiceStatus>::create(participant, topic).value();
  auto publisher = StatusPublisher::create(participant, "gauges", "g-1").value();
  MetricsSnapshot m;
  m.counters = {{"finite", 7}, {"unbounded", INFINITY}, {"unknown", NAN}};
  bool got = false;
  double finite = -1;
  int others = 0;
  for (auto until = std::chrono::steady_clock::now() + 10s;
       !got && std::chrono::steady_clock::now() < until;) {
    ASSERT_TRUE(publisher.publish(studio_SERVICE_RUNNING, NodeHealth{}, m).has_value());
    std::this_thread::sleep_for(50ms);
    for (auto& s : reader.take()) {
      if (!s.meta.valid_data || std::string(s.data->service) != "gauges") continue;
      got = true;
      for (const auto& c : wire::view(s.data->counters)) {
        if (std::string(c.name) == "finite") finite = c.value;
        else ++others;
      }
    }
  }
  ASSERT_TRUE(got) << "the status was refused";
  EXPECT_EQ(finite, 7);
  EXPECT_EQ(others, 0);
}

TEST_F(ServiceTest, KilledServiceLosesLivelinessWhenItsLeaseExpires) {
  auto participant = wire::Participant::create().value();
  auto topic = wire::Topic<studio_ServiceStatus>::create(participant).value();
  auto reader = wire::Reader<studio_ServiceStatus>::create(participant, topic).value();
  const std::string path = write_config("instance: doomed\nstatus_period: 0.2\n");
  auto& p = spawn("probe", "runtime/probe_service", {"--config", path});
  ASSERT_TRUE(p.wait_ready(20s)) << p.log();
  auto deadline = std::chrono::steady_clock::now() + 15s;
  bool heard = false;
  while (!heard && std::chrono::steady_clock::now() < deadline) {
    for (auto& s : reader.take()) heard |= s.meta.valid_data && s.meta.alive;
    std::this_thread::sleep_for(50ms);
  }
  ASSERT_TRUE(heard);
  ASSERT_EQ(reader.alive_writers(), 1u);

  ASSERT_EQ(::kill(p.pid(), SIGKILL), 0);
  const auto killed = std::chrono::steady_clock::now();
  bool not_alive = false;
  deadline = killed + 10s;
  while (!(not_alive && reader.alive_writers() == 0) && std::chrono::steady_clock::now() < deadline) {
    for (auto& s : reader.take()) not_alive |= !s.meta.alive;
    std::this_thread::sleep_for(20ms);
  }
  const double gone_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  EXPECT_TRUE(not_alive);
  EXPECT_EQ(reader.alive_writers(), 0u);
  // Found by the lease, not by a goodbye message (which would take milliseconds), and soon after.
  EXPECT_GT(gone_s, 1.0);
  EXPECT_LT(gone_s, 6.0);
  std::printf("status writer gone %.2f s after kill -9 (lease 3 s)\n", gone_s);
}

TEST_F(ServiceTest, PingsTheWatchdogWhenAsked) {
  const std::string path = write_config("status_period: 5\n");
  auto opts = testing::Process::Options{.name = "probe",
                                        .binary = testing::built_binary("runtime/probe_service"),
                                        .args = {"--config", path},
                                        .env = dds_.env(),
                                        .dir = dir_};
  opts.env.emplace_back("WATCHDOG_USEC", "200000");  // 0.2 s: pings at least every 0.1 s
  auto p = testing::Process::start(opts).value();
  ASSERT_TRUE(p.wait_ready(20s)) << p.log();
  int pings = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 1s)
    if (auto n = p.next_notification(300ms); n && n->find("WATCHDOG=1") != std::string::npos) ++pings;
  EXPECT_GE(pings, 5);  // ≥ 10 expected in 1 s; 5 leaves room for a loaded machine
  EXPECT_EQ(p.stop(), 0);
}

}  // namespace
}  // namespace studio::runtime
