// scene_server_bench: command → change seen by every reader, through a real studio-scene process
// on loopback (issue 14 Done-when: p99 <= 10 ms).
//
// Method: studio-scene runs in a private domain of the loopback profile (clock.source commands,
// so only the commands change the scene). This process holds the command writer and two reader
// participants of studio/scene/node. Each iteration sends SET_TRANSFORM of node "probe" with a
// fresh translation and stamps the time; each reader's data-available listener stamps the arrival
// of that translation. Latency = last reader's arrival − send. 1000 commands, one every 5 ms (so
// each is its own batch: the per-command path, persistence included). A command whose change is
// not seen by both readers within 200 ms counts as lost.
//
// Baseline in the same run: the same server without state_dir (nopersist_* counters); the
// measured case persists (state_dir): the write-ahead copy written before every publication,
// the durable copy (fsync) by the syncer thread off the critical path. Counters: p50_ms, p99_ms,
// max_ms, lost, nopersist_p50_ms, nopersist_p99_ms, nopersist_max_ms, nopersist_lost, and
// ratio_p99 = p99 / nopersist p99.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

#include "harness/process.h"
#include "scene/command.h"
#include "wire/endpoint.h"
#include "wire/scene_convert.h"

namespace studio::scene {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
constexpr int kCommands = 1000;

struct Stats {
  double p50_ms = 0, p99_ms = 0, max_ms = 0;
  int lost = 0;
};

// A reader participant whose listener stamps when translation.x == i arrives.
struct Reader {
  wire::Participant participant = wire::Participant::create().value();
  wire::Topic<studio_SceneNode> topic = wire::Topic<studio_SceneNode>::create(participant).value();
  wire::Reader<studio_SceneNode> reader =
      wire::Reader<studio_SceneNode>::create(participant, topic).value();
  std::vector<std::atomic<int64_t>> arrival = std::vector<std::atomic<int64_t>>(kCommands + 1);

  Reader() {
    (void)reader.on_data_available([this] {
      reader.visit([this](const studio_SceneNode& n, const wire::SampleMeta& m) {
        if (!m.valid_data) return;
        const double x = n.translation[0];
        if (x >= 1 && x <= kCommands && x == double(int(x)))
          arrival[std::size_t(x)].store(Clock::now().time_since_epoch().count());
      });
    });
  }
};

Stats run(bool persist, const testing::DdsDomain& dds, const std::filesystem::path& dir) {
  const auto config = dir / (persist ? "persist.yaml" : "memory.yaml");
  std::ofstream(config) << "instance: bench\nclock: {source: commands}\n"
                        << (persist ? "state_dir: " + (dir / "state").string() + "\n" : "");
  auto server = testing::Process::start({.name = persist ? "scene-persist" : "scene-memory",
                                         .binary = testing::built_binary("scene/studio-scene"),
                                         .args = {"--config", config.string()},
                                         .env = dds.env(),
                                         .dir = dir});
  if (!server) throw std::runtime_error(server.error().message);
  if (!server->wait_ready(20s))
    throw std::runtime_error("studio-scene not ready: " + server->log());

  wire::Participant p = wire::Participant::create().value();
  auto topic = wire::Topic<studio_SceneCommand>::create(p).value();
  auto writer = wire::Writer<studio_SceneCommand>::create(p, topic).value();
  Reader a, b;
  if (!writer.wait_for_readers(1, 10s)) throw std::runtime_error("server did not match");

  wire::Owned<studio_SceneCommand> cmd;
  auto send = [&](const Command& c, uint64_t id) {
    (void)wire::from_core(c, *cmd);
    wire::set(cmd->sender, "bench");
    cmd->command_id = id;
    if (!writer.write(*cmd)) throw std::runtime_error("write failed");
  };
  Node probe;
  probe.id = "probe";
  probe.kind = NodeKind::group;
  send(Command{0, AddNode{probe}}, 1);
  // Both readers have the node before timing starts.
  for (auto deadline = Clock::now() + 10s; Clock::now() < deadline;) {
    if (a.reader.matched_writers() && b.reader.matched_writers()) break;
    std::this_thread::sleep_for(10ms);
  }
  std::this_thread::sleep_for(200ms);

  std::vector<double> ms;
  Stats s;
  for (int i = 1; i <= kCommands; ++i) {
    Transform t;
    t.translation = {double(i), 0, 0};
    const int64_t sent = Clock::now().time_since_epoch().count();
    send(Command{i, SetTransform{"probe", t}}, uint64_t(i) + 1);
    const auto deadline = Clock::now() + 200ms;
    int64_t ta = 0, tb = 0;
    while (Clock::now() < deadline) {
      ta = a.arrival[std::size_t(i)].load();
      tb = b.arrival[std::size_t(i)].load();
      if (ta && tb) break;
      std::this_thread::sleep_for(20us);
    }
    if (ta && tb)
      ms.push_back(double(std::max(ta, tb) - sent) * 1e-6);
    else
      ++s.lost;
    std::this_thread::sleep_until(Clock::time_point(Clock::duration(sent)) + 5ms);
  }
  server->stop();
  std::sort(ms.begin(), ms.end());
  if (!ms.empty()) {
    s.p50_ms = ms[ms.size() / 2];
    s.p99_ms = ms[std::min(ms.size() - 1, std::size_t(double(ms.size()) * 0.99))];
    s.max_ms = ms.back();
  }
  return s;
}

void BM_SceneCommandToEveryReader(benchmark::State& state) {
  const auto dds = testing::DdsDomain::unique();
  dds.apply_to_this_process();
  const auto dir = testing::make_test_dir("scene_server_bench");
  Stats base, persisted;
  for (auto _ : state) {
    base = run(false, dds, dir);
    persisted = run(true, dds, dir);
  }
  state.counters["p50_ms"] = persisted.p50_ms;
  state.counters["p99_ms"] = persisted.p99_ms;
  state.counters["max_ms"] = persisted.max_ms;
  state.counters["lost"] = persisted.lost;
  state.counters["nopersist_p50_ms"] = base.p50_ms;
  state.counters["nopersist_p99_ms"] = base.p99_ms;
  state.counters["nopersist_max_ms"] = base.max_ms;
  state.counters["nopersist_lost"] = base.lost;
  state.counters["ratio_p99"] = base.p99_ms > 0 ? persisted.p99_ms / base.p99_ms : 0;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}
BENCHMARK(BM_SceneCommandToEveryReader)->Iterations(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace studio::scene

BENCHMARK_MAIN();
