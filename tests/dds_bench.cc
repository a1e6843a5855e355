// dds_bench: latency of a 4 KB best-effort mask between two processes on loopback at 1 kHz
// (issue 2 done-when: p50 <= 100 us, p99 <= 500 us, zero loss), against a raw UDP ping-pong of
// the same bytes between the same two kinds of process, in the same run.
//
// Method: this process and a wire_peer ("bench-echo") join a private domain of the loopback
// profile. Every millisecond this process writes an AlphaMask (MASK_CODEC, 704x576, ~4 KB of
// codec bytes; validated by the mask decoder on both sides) to studio/bench/ping with the mask
// QoS row (best-effort, keep-last 1); the peer writes it back unchanged to studio/bench/pong.
// One-way latency = round trip / 2 (both ends validate, so this includes one validation).
// A ping without its pong within 100 ms counts as lost. The baseline does the same with UDP
// datagrams to "wire_peer udp-echo". Counters: p50_us, p99_us, max_us, lost (DDS), udp_p50_us,
// udp_p99_us, udp_lost, ratio_p50 / ratio_p99 (DDS / UDP), bytes.
//
// Two delivery modes, both measured: /waitset (the reader's waitset wakes an application
// thread, as the service nodes do today: two thread wake-ups per hop) and /listener (the
// reader's data-available callback runs on Cyclone's receive thread; the peer echoes from it and
// this process stamps the arrival in it: one wake-up per hop, like the UDP baseline).
//
// Scheduling: the studio runs its latency-critical services SCHED_FIFO on a dedicated core (as a
// systemd unit would with CPUSchedulingPolicy=fifo and CPUAffinity). When allowed (root or
// CAP_SYS_NICE) this bench measures that configuration: itself and both peers (they inherit it)
// SCHED_FIFO 50 on the last CPU, so a hop never waits for a busy time-shared CPU nor for an
// inter-processor wake-up, DDS and UDP alike. Counter `realtime` says which configuration ran;
// STUDIO_BENCH_REALTIME=0 measures the default time-sharing scheduler instead.

#include <arpa/inet.h>
#include <benchmark/benchmark.h>
#include <netinet/in.h>
#include <poll.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "core/mask_codec.h"
#include "harness/process.h"
#include "wire/endpoint.h"

namespace {

using namespace studio;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr int kWarmup = 300;
constexpr int kPings = 3000;  // 3 s at 1 kHz
constexpr auto kPeriod = 1ms;
constexpr auto kReplyTimeout = 100ms;

int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// A 704x576 mask whose kRuns encoding is about 4 KB (the paper's mask size).
std::vector<uint8_t> four_kb_mask() {
  std::mt19937 rng(7);
  std::vector<uint8_t> best;
  for (int rows = 100; rows <= 576; rows += 4) {
    RunMask m(704, 576);
    rng.seed(7);
    for (int y = 0; y < rows; ++y) {
      int x = 100 + int(rng() % 50);
      for (int k = 0; k < 3; ++k) {
        const int len = 20 + int(rng() % 60);
        m.push_run(y, x, x + len);
        x += len + 10 + int(rng() % 40);
      }
    }
    m.finish();
    auto bytes = encode_mask(m, MaskCoding::kRuns);
    if (bytes.size() > 4096) break;
    best = std::move(bytes);
  }
  return best;
}

struct Stats {
  double p50_us = 0, p99_us = 0, max_us = 0;
  int lost = 0;
};

Stats summarize(std::vector<double> one_way_us, int lost) {
  Stats s;
  s.lost = lost;
  if (one_way_us.empty()) return s;
  std::sort(one_way_us.begin(), one_way_us.end());
  auto at = [&](double q) {
    return one_way_us[std::min(one_way_us.size() - 1, size_t(q * one_way_us.size()))];
  };
  s.p50_us = at(0.50);
  s.p99_us = at(0.99);
  s.max_us = one_way_us.back();
  return s;
}

// Runs warmup + kPings paced pings; ping(i) sends, pong(i, deadline) waits for the reply and
// returns the round trip in ns (or -1).
template <class Ping, class Pong>
Stats paced(Ping&& ping, Pong&& pong) {
  std::vector<double> one_way;
  int lost = 0;
  auto next = Clock::now();
  for (int i = 0; i < kWarmup + kPings; ++i) {
    next += kPeriod;
    std::this_thread::sleep_until(next);
    ping(i);
    const int64_t rtt = pong(i, Clock::now() + kReplyTimeout);
    if (i < kWarmup) continue;
    if (rtt < 0)
      ++lost;
    else
      one_way.push_back(double(rtt) / 2e3);
  }
  return summarize(std::move(one_way), lost);
}

Stats run_udp(testing::Process& peer, int port, const std::vector<uint8_t>& payload) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(uint16_t(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::vector<uint8_t> msg(payload.size() + 16), reply(65536);
  auto ping = [&](int i) {
    const int64_t t = now_ns();
    std::memcpy(msg.data(), &i, sizeof i);
    std::memcpy(msg.data() + 8, &t, sizeof t);
    std::memcpy(msg.data() + 16, payload.data(), payload.size());
    sendto(fd, msg.data(), msg.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  };
  auto pong = [&](int i, Clock::time_point deadline) -> int64_t {
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left.count() < 0) return -1;
      pollfd pfd{fd, POLLIN, 0};
      if (poll(&pfd, 1, int(left.count()) + 1) <= 0) return -1;
      const ssize_t n = recv(fd, reply.data(), reply.size(), 0);
      int id = -1;
      int64_t t = 0;
      if (n >= 16) {
        std::memcpy(&id, reply.data(), sizeof id);
        std::memcpy(&t, reply.data() + 8, sizeof t);
      }
      if (id == i) return now_ns() - t;  // stale replies of timed-out pings are skipped
    }
  };
  Stats s = paced(ping, pong);
  close(fd);
  (void)peer;
  return s;
}

Stats run_dds(const std::vector<uint8_t>& payload, bool listener) {
  auto p = wire::Participant::create().value();
  auto ping_topic = wire::Topic<studio_AlphaMask>::create(p, "studio/bench/ping").value();
  auto pong_topic = wire::Topic<studio_AlphaMask>::create(p, "studio/bench/pong").value();
  auto writer = wire::Writer<studio_AlphaMask>::create(p, ping_topic).value();
  auto reader = wire::Reader<studio_AlphaMask>::create(p, pong_topic).value();
  auto ws = wire::WaitSet::create(p).value();
  ws.attach(reader, 1).value();
  // Listener mode: the callback stamps the arrival of pong `want` (-1: none yet).
  std::mutex mu;
  std::condition_variable cv;
  uint64_t want = 0;
  int64_t arrived_rtt = -1;
  if (listener) {
    reader
        .on_data_available([&] {
          reader.visit([&](const studio_AlphaMask& m, const wire::SampleMeta& meta) {
            const int64_t t = now_ns();
            std::lock_guard lock(mu);
            if (meta.valid_data && m.frame == want) {
              arrived_rtt = t - m.capture_ns;
              cv.notify_one();
            }
          });
        })
        .value();
  }
  if (!writer.wait_for_readers(1, 15s)) throw std::runtime_error("dds_bench: peer never matched");
  const auto deadline = Clock::now() + 15s;
  while (reader.matched_writers() < 1 && Clock::now() < deadline) std::this_thread::sleep_for(5ms);

  wire::Owned<studio_AlphaMask> mask;
  wire::set(mask->camera_id, "cam0");
  mask->width = 704;
  mask->height = 576;
  mask->encoding = studio_MASK_CODEC;
  wire::assign(mask->data, payload);
  auto ping = [&](int i) {
    {
      std::lock_guard lock(mu);
      want = uint64_t(i);
      arrived_rtt = -1;
    }
    mask->frame = uint64_t(i);
    mask->capture_ns = now_ns();
    (void)writer.write(*mask);
  };
  auto pong = [&](int i, Clock::time_point until) -> int64_t {
    if (listener) {
      std::unique_lock lock(mu);
      cv.wait_until(lock, until, [&] { return arrived_rtt >= 0; });
      return arrived_rtt;
    }
    int64_t rtt = -1;
    while (rtt < 0) {
      const auto left = until - Clock::now();
      if (left <= Clock::duration::zero()) return -1;
      ws.wait(left);
      reader.visit([&](const studio_AlphaMask& m, const wire::SampleMeta& meta) {
        if (meta.valid_data && m.frame == uint64_t(i)) rtt = now_ns() - m.capture_ns;
      });
    }
    return rtt;
  };
  Stats s = paced(ping, pong);
  if (listener) reader.on_data_available(nullptr).value();
  return s;
}

bool g_realtime = false;

// SCHED_FIFO on the last CPU for this process and everything it starts later (threads, peers).
bool enter_realtime() {
  if (const char* e = std::getenv("STUDIO_BENCH_REALTIME"); e && std::string(e) == "0") return false;
  cpu_set_t one;
  CPU_ZERO(&one);
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  CPU_SET(int(cpus > 0 ? cpus - 1 : 0), &one);
  const sched_param prio{.sched_priority = 50};
  if (sched_setaffinity(0, sizeof one, &one) != 0 || sched_setscheduler(0, SCHED_FIFO, &prio) != 0) {
    std::fprintf(stderr, "dds_bench: no real-time scheduling here (%s); measuring time-sharing\n",
                 std::strerror(errno));
    return false;
  }
  return true;
}

void BM_Mask4kLoopback1kHz(benchmark::State& state) {
  const auto dds = testing::DdsDomain::unique();
  dds.apply_to_this_process();
  const auto dir = testing::make_test_dir("dds_bench");
  const auto payload = four_kb_mask();
  const int port = 20000 + int(getpid() % 20000);
  auto start = [&](const std::string& name, std::vector<std::string> args) {
    auto p = testing::Process::start({.name = name,
                                      .binary = testing::built_binary("tests/wire_peer"),
                                      .args = std::move(args),
                                      .env = dds.env(),
                                      .dir = dir});
    if (!p) throw std::runtime_error(p.error().message);
    if (!p->wait_ready(15s)) throw std::runtime_error(name + " not ready; log: " + p->log());
    return std::move(*p);
  };
  auto udp_peer = start("udp-echo", {"udp-echo", std::to_string(port)});
  const bool listener = state.range(0) == 1;
  std::vector<std::string> echo_args{"bench-echo"};
  if (listener) echo_args.push_back("--listener");
  auto dds_peer = start("bench-echo", echo_args);
  Stats d, u;
  for (auto _ : state) {
    u = run_udp(udp_peer, port, payload);
    d = run_dds(payload, listener);
  }
  state.counters["bytes"] = double(payload.size());
  state.counters["realtime"] = g_realtime ? 1 : 0;
  state.counters["p50_us"] = d.p50_us;
  state.counters["p99_us"] = d.p99_us;
  state.counters["max_us"] = d.max_us;
  state.counters["lost"] = d.lost;
  state.counters["udp_p50_us"] = u.p50_us;
  state.counters["udp_p99_us"] = u.p99_us;
  state.counters["udp_lost"] = u.lost;
  state.counters["ratio_p50"] = u.p50_us > 0 ? d.p50_us / u.p50_us : 0;
  state.counters["ratio_p99"] = u.p99_us > 0 ? d.p99_us / u.p99_us : 0;
  dds_peer.stop();
  udp_peer.stop();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}
BENCHMARK(BM_Mask4kLoopback1kHz)
    ->ArgName("listener")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  g_realtime = enter_realtime();  // before Cyclone creates any thread
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
