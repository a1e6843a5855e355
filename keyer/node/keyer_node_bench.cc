// keyer_node_bench: the keyer service (studio-keyer --config, a real process on loopback) fed
// with 704x576 raw RGB8 simulated-studio frames at 25 fps per camera for N cameras, against the
// baseline of keying + encoding the same frames in this process.
//
// Method: this process renders 8 frames of each of 6 ring cameras (simulated studio) once, starts
// studio-keyer (private DDS domain of the loopback profile, `threads` keying threads), and
// publishes CameraImages paced at 25 fps per camera, capture_ns = the send time, for 4 s. A
// reader thread takes the AlphaMasks and measures latency = arrival - capture_ns (publish ->
// node receive -> copy -> key -> encode -> publish -> this process), the path a mask takes when
// keying runs on another machine than capture (without the wire between machines).
// Counters: sent/s, masks/s, delivered (masks / images sent), lat_p50_ms, lat_p99_ms, dropped
// (the node's frames_dropped: newest-frame-wins replacements), and for the baseline
// key_ms (in-process key + encode per frame); ratio_p50 = lat_p50_ms / key_ms.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <thread>

#include "core/clock.h"
#include "core/mask_codec.h"
#include "harness/process.h"
#include "keyer/keyer.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "wire/endpoint.h"
#include "wire/sample.h"

namespace {

using namespace studio;
using namespace std::chrono_literals;

constexpr int kFramesPerCamera = 8;

const std::vector<std::vector<Image<Rgb8>>>& sim_frames() {
  static std::vector<std::vector<Image<Rgb8>>> frames = [] {
    std::vector<std::vector<Image<Rgb8>>> out(6);
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras()).value();
    std::vector<Image<Rgb8>> images;
    for (int f = 0; f < kFramesPerCamera; ++f) {
      studio.render_all(f * 5, &images, nullptr);
      for (int c = 0; c < 6; ++c) out[c].push_back(images[c]);
    }
    return out;
  }();
  return frames;
}

// Baseline: key + encode one 704x576 frame in process.
void BM_InProcessKeyEncode(benchmark::State& state) {
  const auto& frames = sim_frames();
  auto keyer = keyer::Keyer::create({}).value();
  RunMask mask;
  std::vector<uint8_t> bytes;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& img = frames[i % 6][(i / 6) % kFramesPerCamera];
    ++i;
    (void)keyer.key(img.view(), mask);
    encode_mask(mask, MaskCoding::kRowDelta, bytes);
    benchmark::DoNotOptimize(bytes.data());
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, std::size_t(p * double(v.size())))];
}

void BM_NodeAt25Fps(benchmark::State& state) {
  const int cameras = int(state.range(0));
  const int threads = int(state.range(1));
  const auto& frames = sim_frames();
  // In-process cost of the same work, for the ratio (measured here, not taken from elsewhere).
  double key_ms = 0;
  {
    auto keyer = keyer::Keyer::create({}).value();
    RunMask mask;
    std::vector<uint8_t> bytes;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < 480; ++i) {
      (void)keyer.key(frames[i % 6][(i / 6) % kFramesPerCamera].view(), mask);
      encode_mask(mask, MaskCoding::kRowDelta, bytes);
    }
    key_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() /
        480;
  }

  const auto dir = testing::make_test_dir("keyer_node_bench");
  auto dds = testing::DdsDomain::unique();
  // Another Cyclone profile for both ends (e.g. larger socket buffers): STUDIO_BENCH_DDS_URI.
  if (const char* uri = std::getenv("STUDIO_BENCH_DDS_URI")) dds.config_uri = uri;
  dds.apply_to_this_process();
  std::ofstream(dir / "keyer.yaml")
      << "instance: bench\nstatus_period: 0.5\nthreads: " << threads << "\n";
  auto node = testing::Process::start({.name = "keyer",
                                       .binary = testing::built_binary("keyer/studio-keyer"),
                                       .args = {"--config", (dir / "keyer.yaml").string()},
                                       .env = dds.env(),
                                       .dir = dir});
  if (!node || !node->wait_ready(20s)) {
    state.SkipWithError("studio-keyer did not start");
    return;
  }
  auto p = wire::Participant::create().value();
  auto image_topic = wire::Topic<studio_CameraImage>::create(p).value();
  auto images = wire::Writer<studio_CameraImage>::create(p, image_topic).value();
  auto mask_topic = wire::Topic<studio_AlphaMask>::create(p).value();
  auto masks = wire::Reader<studio_AlphaMask>::create(p, mask_topic).value();
  auto status_topic = wire::Topic<studio_ServiceStatus>::create(p).value();
  auto status = wire::Reader<studio_ServiceStatus>::create(p, status_topic).value();
  auto ws = wire::WaitSet::create(p).value();
  ws.attach(masks, 1).value();
  if (!images.wait_for_readers(1, 10s)) {
    state.SkipWithError("no match");
    return;
  }

  std::vector<wire::Owned<studio_CameraImage>> samples(std::size_t(cameras) * kFramesPerCamera);
  for (int c = 0; c < cameras; ++c)
    for (int f = 0; f < kFramesPerCamera; ++f) {
      auto& s = samples[std::size_t(c) * kFramesPerCamera + f];
      const auto& img = frames[c][f];
      wire::set(s->camera_id, "cam" + std::to_string(c));
      s->width = uint32_t(img.width());
      s->height = uint32_t(img.height());
      s->format = studio_IMAGE_RGB8;
      const auto* px = reinterpret_cast<const uint8_t*>(img.data());
      wire::assign(s->data, std::span<const uint8_t>(px, img.pixels().size() * 3));
    }

  std::vector<double> latencies;
  uint64_t sent = 0;
  double dropped = 0, node_in = 0, missed = 0;
  for (auto _ : state) {
    std::atomic<bool> receiving{true};
    std::thread receiver([&] {
      while (receiving) {
        ws.wait(20ms);
        const int64_t now = realtime_ns();
        masks.visit([&](const studio_AlphaMask& m, const wire::SampleMeta& meta) {
          if (meta.valid_data && m.capture_ns > 0)
            latencies.push_back(double(now - m.capture_ns) * 1e-6);
        });
      }
    });
    const auto start = std::chrono::steady_clock::now();
    const auto period = std::chrono::microseconds(40000);
    for (uint64_t tick = 0; tick < 100; ++tick) {  // 4 s at 25 fps
      std::this_thread::sleep_until(start + tick * period);
      for (int c = 0; c < cameras; ++c) {
        auto& s = samples[std::size_t(c) * kFramesPerCamera + tick % kFramesPerCamera];
        s->frame = tick;
        s->capture_ns = realtime_ns();
        (void)images.write(*s);
        ++sent;
      }
    }
    std::this_thread::sleep_for(300ms);
    receiving = false;
    receiver.join();
  }
  // The node's own count of replaced (dropped) frames, from its status.
  const auto until = std::chrono::steady_clock::now() + 2s;
  while (std::chrono::steady_clock::now() < until) {
    for (auto& s : status.take())
      if (s.meta.valid_data) {
        for (const auto& c : wire::view(s.data->counters)) {
          const std::string name(wire::str(c.name));
          if (name == "frames_dropped") {
            dropped = c.value;
          } else if (name == "frames_missed") {
            missed = c.value;
          } else if (name == "images_in") {
            node_in = c.value;
          }
        }
      }
    std::this_thread::sleep_for(100ms);
  }
  node->stop();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);

  const double seconds = 4.0 * double(state.iterations());
  state.counters["cameras"] = cameras;
  state.counters["sent_per_s"] = double(sent) / seconds;
  state.counters["masks_per_s"] = double(latencies.size()) / seconds;
  state.counters["delivered"] = sent ? double(latencies.size()) / double(sent) : 0;
  state.counters["dropped"] = dropped;
  state.counters["missed"] = missed;  // the node's count of frame numbers it never received
  state.counters["node_in"] = sent ? node_in / double(sent) : 0;  // images that reached the node
  state.counters["lat_p50_ms"] = percentile(latencies, 0.5);
  state.counters["lat_p99_ms"] = percentile(latencies, 0.99);
  state.counters["key_ms"] = key_ms;
  state.counters["ratio_p50"] = key_ms > 0 ? percentile(latencies, 0.5) / key_ms : 0;
}

BENCHMARK(BM_InProcessKeyEncode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NodeAt25Fps)
    ->ArgsProduct({{1, 2, 4, 6}, {1}})
    ->Args({6, 2})
    ->ArgNames({"cameras", "threads"})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
