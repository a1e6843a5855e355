// security_bench: what DDS Security costs (issue 19 item 3). The same exchange, plain and secured,
// in the same run: a 4 KB AlphaMask (the paper's mask size, the mask topic's QoS row) from this
// process to a wire_peer "bench-echo" and back, paced at 1 kHz, over the loopback profile.
//
//   plain:  loopback.xml, one DDS domain
//   secure: loopback.xml + secure.xml (authentication, access control, AES-GCM on discovery,
//           liveliness, payload and metadata: the studio governance of deploy/security/make-pki)
//           in another domain, both ends with identities of role `bench` (studio/bench/*)
//
// One-way latency = round trip / 2 (both ends encrypt and decrypt once per hop: one hop's cost).
// Counters per case: p50_us, p99_us, lost (no pong within 100 ms), match_ms (participant creation
// to both endpoints matched: for the secure case the plugins' start, the handshake and the
// encrypted discovery; the echo peer runs already);
// on the secure case also ratio_p50 / ratio_p99 (secure / plain, same run).
// Both cases run in one benchmark so the ratio comes from one machine state.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/mask_codec.h"
#include "harness/process.h"
#include "wire/endpoint.h"

namespace {

using namespace studio;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr int kWarmup = 300;
constexpr int kPings = 3000;  // 3 s at 1 kHz
constexpr auto kReplyTimeout = 100ms;

int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// A 704x576 silhouette-like mask whose run encoding is close to 4 KB (the paper's size).
std::vector<uint8_t> mask_bytes() {
  std::vector<uint8_t> best;
  for (int rows = 100; rows <= 576; rows += 4) {
    RunMask m(704, 576);
    std::mt19937 rng(7);
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
  double p50_us = 0, p99_us = 0, match_ms = 0;
  int lost = 0;
};

// Pings through `p` (already in its domain) to an echo peer; returns the one-way latencies.
// t0: just before the participant was created (match_ms includes authentication).
Stats ping_pong(const wire::Participant& p, Clock::time_point t0) {
  auto ping_topic = wire::Topic<studio_AlphaMask>::create(p, "studio/bench/ping").value();
  auto pong_topic = wire::Topic<studio_AlphaMask>::create(p, "studio/bench/pong").value();
  auto writer = wire::Writer<studio_AlphaMask>::create(p, ping_topic).value();
  auto reader = wire::Reader<studio_AlphaMask>::create(p, pong_topic).value();
  auto ws = wire::WaitSet::create(p).value();
  ws.attach(reader, 1).value();
  if (!writer.wait_for_readers(1, 30s)) throw std::runtime_error("security_bench: no echo peer");
  for (const auto end = Clock::now() + 30s; reader.matched_writers() < 1 && Clock::now() < end;)
    std::this_thread::sleep_for(1ms);
  Stats s;
  s.match_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();

  wire::Owned<studio_AlphaMask> mask;
  wire::set(mask->camera_id, "cam0");
  mask->width = 704;
  mask->height = 576;
  mask->encoding = studio_MASK_CODEC;  // both ends validate it with the mask decoder
  wire::assign(mask->data, mask_bytes());

  std::vector<double> one_way;
  auto next = Clock::now();
  for (int i = 0; i < kWarmup + kPings; ++i) {
    next += 1ms;
    std::this_thread::sleep_until(next);
    mask->frame = uint64_t(i);
    mask->capture_ns = now_ns();
    (void)writer.write(*mask);
    int64_t rtt = -1;
    for (const auto until = Clock::now() + kReplyTimeout; rtt < 0;) {
      const auto left = until - Clock::now();
      if (left <= Clock::duration::zero()) break;
      ws.wait(left);
      reader.visit([&](const studio_AlphaMask& m, const wire::SampleMeta& meta) {
        if (meta.valid_data && m.frame == uint64_t(i)) rtt = now_ns() - m.capture_ns;
      });
    }
    if (i < kWarmup) continue;
    if (rtt < 0)
      ++s.lost;
    else
      one_way.push_back(double(rtt) / 2e3);
  }
  std::sort(one_way.begin(), one_way.end());
  if (!one_way.empty()) {
    s.p50_us = one_way[one_way.size() / 2];
    s.p99_us = one_way[std::min(one_way.size() - 1, size_t(0.99 * double(one_way.size())))];
  }
  return s;
}

void BM_Mask4kPlainVsSecure(benchmark::State& state) {
  const fs::path dir = testing::make_test_dir("security_bench");
  const fs::path src(STUDIO_SOURCE_DIR);
  const std::string pki = (dir / "pki").string();
  const std::string make = src.string() + "/deploy/security/make-pki --out '" + pki +
                           "' --domains 0-230 --role 'bench:studio/bench/*:studio/bench/*' "
                           "--identity bench-ping --identity bench-echo >/dev/null 2>&1";
  if (std::system(make.c_str()) != 0) throw std::runtime_error("security_bench: make-pki failed");
  const std::string secure_xml = "file://" + (fs::path(STUDIO_BINARY_DIR) / "deploy/dds/secure.xml").string();

  const auto plain = testing::DdsDomain::unique();
  auto secure = testing::DdsDomain::unique();
  while (secure.domain_id == plain.domain_id) secure = testing::DdsDomain::unique();
  testing::Env secure_env = secure.env();
  for (auto& [k, v] : secure_env)
    if (k == "CYCLONEDDS_URI") v += "," + secure_xml;
  secure_env.emplace_back("STUDIO_SECURITY_DIR", pki);
  secure_env.emplace_back("STUDIO_IDENTITY", "bench-echo");

  auto start = [&](const std::string& name, const testing::Env& env) {
    auto p = testing::Process::start({.name = name,
                                      .binary = testing::built_binary("tests/wire_peer"),
                                      .args = {"bench-echo"},
                                      .env = env,
                                      .dir = dir});
    if (!p) throw std::runtime_error(p.error().message);
    if (!p->wait_ready(30s)) throw std::runtime_error(name + " not ready: " + p->log());
    return std::move(*p);
  };
  auto plain_peer = start("echo-plain", plain.env());
  auto secure_peer = start("echo-secure", secure_env);

  // This process: the tag of each domain and the identity of its secure participant. Each
  // participant is created just before its run, so the secure handshake overlaps nothing.
  Stats a, b;
  for (auto _ : state) {
    setenv("STUDIO_DDS_TAG", plain.tag.c_str(), 1);
    const auto t_plain = Clock::now();
    {
      auto plain_p = wire::Participant::create(plain.domain_id, plain.config_uri).value();
      a = ping_pong(plain_p, t_plain);
    }
    setenv("STUDIO_DDS_TAG", secure.tag.c_str(), 1);
    setenv("STUDIO_SECURITY_DIR", pki.c_str(), 1);
    setenv("STUDIO_IDENTITY", "bench-ping", 1);
    const auto t_secure = Clock::now();
    auto secure_p =
        wire::Participant::create(secure.domain_id, secure.config_uri + "," + secure_xml).value();
    b = ping_pong(secure_p, t_secure);
  }
  state.counters["plain_p50_us"] = a.p50_us;
  state.counters["plain_p99_us"] = a.p99_us;
  state.counters["plain_lost"] = a.lost;
  state.counters["plain_match_ms"] = a.match_ms;
  state.counters["secure_p50_us"] = b.p50_us;
  state.counters["secure_p99_us"] = b.p99_us;
  state.counters["secure_lost"] = b.lost;
  state.counters["secure_match_ms"] = b.match_ms;
  state.counters["ratio_p50"] = a.p50_us > 0 ? b.p50_us / a.p50_us : 0;
  state.counters["ratio_p99"] = a.p99_us > 0 ? b.p99_us / a.p99_us : 0;
  secure_peer.stop();
  plain_peer.stop();
  std::error_code ec;
  fs::remove_all(dir, ec);
}
BENCHMARK(BM_Mask4kPlainVsSecure)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
