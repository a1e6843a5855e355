// Faults in a running studio (issue 19 item 6), every service started as its systemd unit starts
// it (studio_under_test.h):
//  - kill -9 of each service (a capture server, the hull, the tracker, the scene server) and a
//    restart with its unit's command line: its first status reaches the others within 2 s of the
//    restart, the pipeline resumes (that stage's output flows again), the services whose peer
//    vanished kept running and said so (the hull DEGRADED with a camera missing, the tracker
//    DEGRADED with no segments), and `studioctl status --watch` reports the restart with the gap;
//  - a rogue writer flooding 10 000 malformed masks per second: rejected and counted by the hull
//    (masks_rejected_malformed in its status) while the segments keep >= 90 % of their rate;
//  - the systemd protocol, the test playing systemd (NOTIFY_SOCKET, WATCHDOG_USEC): every service
//    sends READY=1, pings WATCHDOG=1 at least every half interval and STOPPING=1 on SIGTERM; a
//    stalled main loop (studio_stall_service: service_main with a health() that blocks on demand)
//    stops the pings, they resume when it unstalls, and systemd's SIGABRT + restart brings it back;
//    a wedged service-loop thread (the main loop still running) stops them too: the runtime pings
//    only while every ServiceLoop has turned within loop_stall (runtime/liveness.h).
// Each test prints one FAULT/FLOOD line with its figures (BENCHMARKS.md, operations).
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "studio_under_test.h"
#include "studioctl/testing/json.h"
#include "studioctl/testing/run.h"

namespace studio::faults {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Json = ctl::testing::Json;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

struct Victim {
  const char* name;      // process name in the test
  const char* unit;      // its unit
  const char* instance;  // %i
  const char* status;    // service:instance in studio/service/status
};

void PrintTo(const Victim& v, std::ostream* os) { *os << v.name; }

class KillAndRestart : public StudioTest, public ::testing::WithParamInterface<Victim> {};

TEST_P(KillAndRestart, RejoinsWithin2sAndThePipelineResumes) {
  const Victim v = GetParam();
  const bool scene = std::string(v.name) == "scene";
  start_studio(scene);
  Monitor mon;
  ASSERT_TRUE(mon.until([&] { return mon.segment_frames >= 10 && mon.head_updates >= 5; }, 30s))
      << "the pipeline did not start: " << mon.segment_frames << " segment frames, "
      << mon.head_updates << " head updates";
  const double before_hz = mon.segments_hz(2s);
  ASSERT_TRUE(mon.status.count(v.status)) << v.status;
  auto& watch = spawn("watch", "deploy/studioctl/studioctl", {"status", "--watch", "30", "--json"});
  std::this_thread::sleep_for(1s);  // the watcher has heard everyone

  testing::Process* victim = find(v.name);
  ASSERT_NE(victim, nullptr);
  const int old_pid = victim->pid();
  ASSERT_EQ(::kill(old_pid, SIGKILL), 0);
  ASSERT_EQ(victim->wait_exit(5s), -SIGKILL);
  const auto killed = Clock::now();

  // While it is gone (longer than the status topic's 3 s liveliness lease): the others keep
  // running and publishing their status; those that lost their peer report it.
  mon.degraded_seen.clear();
  std::this_thread::sleep_for(200ms);
  mon.poll();
  const auto gone_at = Clock::now();
  mon.until([] { return false; }, 3500ms);
  for (const auto& [key, st] : mon.status) {
    if (key == v.status || key.starts_with("studioctl")) continue;
    EXPECT_GT(st.at, gone_at) << key << " stopped reporting after " << v.name << " was killed";
  }
  for (auto& p : processes_) {
    if (&p != victim && p.name() != "watch") {
      EXPECT_TRUE(p.running()) << p.name() << " died too";
    }
  }
  if (std::string(v.name) == "cam1") {
    EXPECT_TRUE(mon.degraded_seen.contains("hull:hull"))
        << "the hull did not report a camera missing";
    EXPECT_GT(mon.segments_hz(1s), 5) << "the hull must go on with 3 of 4 cameras";
  }
  if (std::string(v.name) == "hull") {
    EXPECT_TRUE(mon.degraded_seen.contains("tracker:tracker"))
        << "the tracker did not report that no segments arrive";
  }

  // Restart as systemd does (Restart=on-failure): the unit's command line.
  const auto restart_at = Clock::now();
  auto& again = start_unit(v.name, v.unit, v.instance);
  ASSERT_TRUE(again.wait_ready(30s)) << again.log();
  const double ready_s = seconds(Clock::now() - restart_at);
  ASSERT_TRUE(mon.until([&] { return mon.first_status_of_pid.contains(again.pid()); }, 10s))
      << "no status of the restarted " << v.name;
  const double rejoin_s = seconds(mon.first_status_of_pid.at(again.pid()) - restart_at);
  EXPECT_LE(rejoin_s, 2.0) << v.name << " rejoined " << rejoin_s << " s after its restart";

  // The pipeline resumes: this stage's output flows again, and the end of the pipeline too.
  const uint64_t segments_then = mon.segment_frames, heads_then = mon.head_updates;
  const uint64_t cam1_then = mon.mask_frame["cam1"];
  EXPECT_TRUE(mon.until(
      [&] {
        return mon.segment_frames >= segments_then + 10 && mon.head_updates >= heads_then + 5 &&
               mon.mask_frame["cam1"] > cam1_then;
      },
      15s))
      << "segments +" << mon.segment_frames - segments_then << ", heads +"
      << mon.head_updates - heads_then;
  const double resume_s = seconds(mon.last_head_at - restart_at);
  const double after_hz = mon.segments_hz(2s);
  EXPECT_GE(after_hz, 0.7 * before_hz) << "before " << before_hz << " Hz";

  if (scene) {  // the restarted server resumed its persisted scene: this host holds it again
    auto h = ctl::testing::run_studioctl({"scene", "hash", "--json", "--wait", "10"},
                                         dir_ / "scene-hash.err");
    EXPECT_EQ(h.code, 0) << h.err << h.out;
    auto j = ctl::testing::json_lines_of(h.out);
    ASSERT_EQ(j.size(), 1u) << h.out;
    EXPECT_TRUE(j[0].find("consistent")->boolean);
    EXPECT_GT(j[0].find("node_count")->number, 3);
  }

  // studioctl status --watch saw the restart, with the gap between the two processes' statuses.
  watch.stop();
  double gap_s = -1;
  std::stringstream log(watch.log());
  for (std::string line; std::getline(log, line);) {
    auto j = ctl::testing::JsonReader::parse(line);
    if (!j || j->kind != Json::Kind::object) continue;
    if (j->find("event")->string == "restarted" &&
        j->find("service")->string + ":" + j->find("instance")->string == v.status) {
      EXPECT_EQ(int(j->find("old_pid")->number), old_pid);
      EXPECT_EQ(int(j->find("pid")->number), again.pid());
      gap_s = j->find("gap_s")->number;
    }
  }
  const double down_s = seconds(restart_at - killed);
  EXPECT_GE(gap_s, down_s) << "the gap must cover the time it was dead\n" << watch.log();
  EXPECT_LE(gap_s, down_s + ready_s + 1.0) << watch.log();
  std::printf(
      "FAULT %s: kill -9, down %.2f s, restart: READY %.2f s, first status at the others %.2f s, "
      "head updates again %.2f s; studioctl status --watch gap %.2f s; segments %.1f Hz before, "
      "%.1f Hz after\n",
      v.name, down_s, ready_s, rejoin_s, resume_s, gap_s, before_hz, after_hz);
}

INSTANTIATE_TEST_SUITE_P(
    EachService, KillAndRestart,
    ::testing::Values(Victim{"cam1", "studio-capture@.service", "cam1", "capture:cam1"},
                      Victim{"hull", "studio-hull.service", "", "hull:hull"},
                      Victim{"tracker", "studio-tracker.service", "", "tracker:tracker"},
                      Victim{"scene", "studio-scene.service", "", "scene:scene"}),
    [](const auto& info) { return std::string(info.param.name); });

class Flood : public StudioTest {};

// 10 000 malformed masks per second (row_start of the wrong length: the validator's bad_size)
// from a writer in this process, under ten rogue camera ids (a misconfigured or buggy node; an
// attacker is DDS Security's to stop: deploy/security/).
TEST_F(Flood, MalformedMasksAreRejectedAndCountedWhileThePipelineKeepsItsRate) {
  start_studio(false);
  Monitor mon;
  ASSERT_TRUE(mon.until([&] { return mon.segment_frames >= 10; }, 30s));
  const double before_hz = mon.segments_hz(4s);
  mon.poll();
  const uint64_t rejected_before = mon.status["hull:hull"].counters["masks_rejected_malformed"];

  auto p = wire::Participant::create().value();
  auto topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto writer = wire::Writer<studio_AlphaMask>::create(p, topic).value();
  std::atomic<bool> flooding{true};
  std::atomic<uint64_t> sent{0};
  std::thread rogue([&] {
    wire::Owned<studio_AlphaMask> m;
    m->width = 176;
    m->height = 144;
    m->encoding = studio_MASK_RUNS;
    std::vector<uint32_t> rows(10, 0);  // height + 1 entries are required
    wire::assign(m->row_start, rows);
    auto next = Clock::now();
    while (flooding) {
      for (int k = 0; k < 100; ++k) {  // 100 every 10 ms
        wire::set(m->camera_id, "rogue" + std::to_string(k % 10));
        m->frame = sent.load();
        if (writer.write(*m)) ++sent;
      }
      next += 10ms;
      std::this_thread::sleep_until(next);
    }
  });
  const auto t0 = Clock::now();
  const double during_hz = mon.segments_hz(5s);
  flooding = false;
  rogue.join();
  const double rate = double(sent) / seconds(Clock::now() - t0);
  ASSERT_TRUE(mon.until(
      [&] {
        return mon.status["hull:hull"].counters["masks_rejected_malformed"] > rejected_before;
      },
      5s));
  std::this_thread::sleep_for(500ms);
  mon.poll();
  const uint64_t rejected =
      mon.status["hull:hull"].counters["masks_rejected_malformed"] - rejected_before;
  EXPECT_GE(rate, 9000) << "the flood was not 10 000 samples/s";
  EXPECT_GE(during_hz, 0.9 * before_hz) << "before " << before_hz << " Hz";
  // Best effort, keep-last 1 per rogue instance: the hull sees what its reader holds when it
  // wakes; every one of those is refused, none reaches the cut.
  EXPECT_GT(rejected, 1000u);
  for (testing::Process& proc : processes_) EXPECT_TRUE(proc.running()) << proc.name();
  std::printf(
      "FLOOD: %.0f malformed masks/s for 5 s (%llu sent), hull rejected and counted %llu "
      "(masks_rejected_malformed); segments %.1f Hz before, %.1f Hz during (%.0f %%)\n",
      rate, (unsigned long long)sent.load(), (unsigned long long)rejected, before_hz, during_hz,
      100 * during_hz / before_hz);
}

// Notifications of `p` for `d`: the instants of WATCHDOG=1 pings (and whether STOPPING=1 came).
struct Pings {
  std::vector<Clock::time_point> at;
  double max_interval_s() const {
    double m = 0;
    for (std::size_t i = 1; i < at.size(); ++i) m = std::max(m, seconds(at[i] - at[i - 1]));
    return m;
  }
};
Pings collect(testing::Process& p, Clock::duration d) {
  Pings out;
  const auto end = Clock::now() + d;
  while (Clock::now() < end) {
    auto n = p.next_notification(
        std::chrono::duration_cast<std::chrono::milliseconds>(end - Clock::now()) + 1ms);
    if (n && n->find("WATCHDOG=1") != std::string::npos) out.at.push_back(Clock::now());
  }
  return out;
}

class Systemd : public StudioTest {};

TEST_F(Systemd, EveryServiceSendsReadyPingsTheWatchdogAndSaysStopping) {
  const testing::Env watchdog = {{"WATCHDOG_USEC", "1000000"}};  // WatchdogSec=1
  struct Unit {
    const char *name, *unit, *instance;
  };
  for (const Unit u :
       {Unit{"tracker", "studio-tracker.service", ""}, Unit{"hull", "studio-hull.service", ""},
        Unit{"scene", "studio-scene.service", ""},
        Unit{"cam0", "studio-capture@.service", "cam0"}}) {
    SCOPED_TRACE(u.name);
    auto& p = start_unit(u.name, u.unit, u.instance, watchdog);
    ASSERT_TRUE(p.wait_ready(30s)) << p.log();
    const Pings pings = collect(p, 2s);
    EXPECT_GE(pings.at.size(), 4u) << "pings every 0.5 s expected";
    EXPECT_LE(pings.max_interval_s(), 0.9) << "systemd kills a service silent for WatchdogSec=1";
    ASSERT_EQ(::kill(p.pid(), SIGTERM), 0);
    bool stopping = false;
    for (int i = 0; i < 100 && !stopping; ++i)
      if (auto n = p.next_notification(100ms); n && n->find("STOPPING=1") != std::string::npos)
        stopping = true;
    EXPECT_TRUE(stopping);
    EXPECT_EQ(p.wait_exit(15s), 0) << p.log();
    std::printf("SYSTEMD %s: READY, %zu pings in 2 s (max interval %.3f s), STOPPING, exit 0\n",
                u.name, pings.at.size(), pings.max_interval_s());
  }
}

TEST_F(Systemd, AStalledMainLoopStopsThePingsAndARestartBringsItBack) {
  const auto stall = dir_ / "stall";
  std::ofstream(etc_ / "stall.yaml")
      << "instance: stall0\nstatus_period: 0.1\nstall_file: " << stall.string() << "\n";
  const testing::Env env = {{"WATCHDOG_USEC", "500000"}};
  auto start = [&]() -> testing::Process& {
    testing::Env e = dds_.env();
    e.insert(e.end(), env.begin(), env.end());
    auto p = testing::Process::start(
        {.name = "stall",
         .binary = testing::built_binary("deploy/live/studio_stall_service"),
         .args = {"--config", (etc_ / "stall.yaml").string()},
         .env = e,
         .dir = dir_});
    if (!p) throw std::runtime_error(p.error().message);
    processes_.push_back(std::move(*p));
    return processes_.back();
  };
  auto& p = start();
  ASSERT_TRUE(p.wait_ready(30s)) << p.log();
  // Positive control: pings while the loop runs.
  const Pings running = collect(p, 1s);
  EXPECT_GE(running.at.size(), 3u);
  EXPECT_LE(running.max_interval_s(), 0.45);
  // The stall: no ping for three watchdog intervals (systemd would have killed it after one).
  std::ofstream(stall) << "stall\n";
  (void)collect(p, 300ms);  // a ping already on its way
  const Pings stalled = collect(p, 1500ms);
  EXPECT_EQ(stalled.at.size(), 0u) << "a stalled main loop must not ping the watchdog";
  // Unstalled: the pings resume.
  std::filesystem::remove(stall);
  const Pings resumed = collect(p, 1s);
  EXPECT_GE(resumed.at.size(), 2u) << "pings did not resume";
  // Stalled again, and systemd acts: WatchdogSignal (SIGABRT), then Restart=on-failure.
  std::ofstream(stall) << "stall\n";
  (void)collect(p, 300ms);
  EXPECT_EQ(collect(p, 700ms).at.size(), 0u);
  ASSERT_EQ(::kill(p.pid(), SIGABRT), 0);
  EXPECT_EQ(p.wait_exit(10s), -SIGABRT);
  std::filesystem::remove(stall);
  auto& again = start();
  ASSERT_TRUE(again.wait_ready(30s)) << again.log();
  EXPECT_GE(collect(again, 1s).at.size(), 2u);
  std::printf(
      "WATCHDOG: pings every <= %.3f s running, %zu in 1.5 s stalled, %zu in 1 s after the "
      "stall ended; SIGABRT + restart: READY again\n",
      running.max_interval_s(), stalled.at.size(), resumed.at.size());
}

// The main loop keeps running but the node's ServiceLoop thread is stuck in one turn (a handler
// that never returns): the pings must stop all the same, or systemd would never restart a
// service that does nothing. Positive control: the same service, loop turning, keeps pinging.
// (With `loop_stall: 600` in wedge.yaml this test fails: 16 pings in the wedged 1.5 s.)
TEST_F(Systemd, AWedgedServiceLoopThreadStopsThePings) {
  const auto stall = dir_ / "stall", wedge = dir_ / "wedge";
  std::ofstream(etc_ / "wedge.yaml")
      << "instance: wedge0\nstatus_period: 0.1\nstall_file: " << stall.string()
      << "\nwedge_file: " << wedge.string() << "\n";
  testing::Env env = dds_.env();
  env.push_back({"WATCHDOG_USEC", "500000"});  // loop_stall defaults to 0.25 s
  auto started =
      testing::Process::start({.name = "wedge",
                               .binary = testing::built_binary("deploy/live/studio_stall_service"),
                               .args = {"--config", (etc_ / "wedge.yaml").string()},
                               .env = env,
                               .dir = dir_});
  ASSERT_TRUE(started.has_value()) << started.error().message;
  processes_.push_back(std::move(*started));
  testing::Process& p = processes_.back();
  ASSERT_TRUE(p.wait_ready(30s)) << p.log();
  // Positive control: the loop turns (a 20 ms timer), the pings come.
  const Pings healthy = collect(p, 1s);
  EXPECT_GE(healthy.at.size(), 3u);
  EXPECT_LE(healthy.max_interval_s(), 0.45);
  // Wedge the loop thread. The main loop goes on (it says which loop stalled, in STATUS=), but
  // sends no ping.
  std::ofstream(wedge) << "wedge\n";
  std::size_t wedged_pings = 0;
  bool said_stalled = false;
  const auto settle = Clock::now() + 500ms;  // loop_stall 0.25 s + a ping already on its way
  for (auto end = settle + 1500ms; Clock::now() < end;) {
    auto n = p.next_notification(100ms);
    if (!n) continue;
    if (n->find("STATUS=loop 'stall' stalled") != std::string::npos) said_stalled = true;
    if (n->find("WATCHDOG=1") != std::string::npos && Clock::now() > settle) ++wedged_pings;
  }
  EXPECT_TRUE(said_stalled) << "the main loop must name the stalled loop (STATUS=)\n" << p.log();
  EXPECT_EQ(wedged_pings, 0u) << "a wedged loop thread must not let the watchdog be pinged";
  EXPECT_TRUE(p.running());
  EXPECT_NE(p.log().find("loop 'stall' stalled"), std::string::npos) << p.log();
  // Unwedged: the loop turns again and the pings resume.
  std::filesystem::remove(wedge);
  const Pings resumed = collect(p, 1s);
  EXPECT_GE(resumed.at.size(), 2u) << "pings did not resume\n" << p.log();
  std::printf(
      "WATCHDOG wedged loop thread: pings every <= %.3f s healthy, %zu in 1.5 s wedged (main "
      "loop running, STATUS= names the loop), %zu in 1 s after\n",
      healthy.max_interval_s(), wedged_pings, resumed.at.size());
}

}  // namespace
}  // namespace studio::faults
