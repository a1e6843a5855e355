// A capture server's CPU per frame in the demo (issue 20), without DDS: the six simulated cameras
// as deploy/examples/studio/capture-cam*.yaml configure them (ring of 6, 704x576, the `sequence`
// motion, frame numbers of the studio clock now: the demo's poses), each frame rendered by the
// simulated source into a fresh image (capture/sim_source.h), keyed in process with the example
// keyer.yaml options (blue, clip 20/100, edge refinement), its mask coded (row delta), and one
// JPEG (quality 85) every 12.5 frames (image rate 2 Hz at 25 fps).
// BM_CaptureServerFrame/reference:0 uses the default renderer, /reference:1 the pre-issue-20
// renderer (sim::StudioOptions::reference_renderer, bit-identical images): the baseline in the
// same run. Counters, thread CPU ms per camera frame: render_ms, key_ms, code_ms, jpeg_ms and
// total_ms (what one capture server spends per 40 ms frame outside DDS and the take recorder),
// camN_ms the same per camera (the overhead camera cam5 sees the smallest actor);
// x6_ms = 6 * total_ms, the demo's `capture` stage (report.json cpu_budget) minus DDS.
#include <benchmark/benchmark.h>

#include <time.h>

#include <memory>
#include <string>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "capture/sim_source.h"
#include "core/mask_codec.h"
#include "keyer/plate_keyer.h"
#include "sim/cameras.h"

namespace studio::capture {
namespace {

double thread_cpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

struct Server {
  std::unique_ptr<SimFrameSource> source;
  std::unique_ptr<keyer::PlateKeyer> keyer;
  RunMask mask;
  std::vector<uint8_t> mask_bytes, jpeg;
};

void BM_CaptureServerFrame(benchmark::State& state) {
  const bool reference = state.range(0) != 0;
  std::vector<Server> servers;
  const std::vector<Camera> ring = sim::ring_cameras();  // ring: 6, 704x576 (the example configs)
  for (std::size_t i = 0; i < ring.size(); ++i) {
    SimSourceOptions o;
    o.camera = ring[i];
    o.paced = false;  // unpaced: consecutive frames from the studio clock's frame now
    o.studio.reference_renderer = reference;
    Server s;
    s.source = SimFrameSource::create(o).value();
    if (!s.source->start()) state.SkipWithError("source start");
    keyer::KeyerOptions k;  // keyer.yaml: blue, clip_black 20, clip_white 100, edge_refine
    s.keyer = std::make_unique<keyer::PlateKeyer>(keyer::Keyer::create(k).value());
    servers.push_back(std::move(s));
  }
  double render = 0, key = 0, code = 0, jpeg = 0;
  std::vector<double> per_camera(servers.size(), 0.0);
  int64_t frames = 0, keyed = 0, rounds = 0;
  for (auto _ : state) {
    ++rounds;
    for (std::size_t c = 0; c < servers.size(); ++c) {
      Server& s = servers[c];
      double t0 = thread_cpu();
      auto f = s.source->next(std::chrono::milliseconds(1000));
      const double t1 = thread_cpu();
      if (!f || !*f) {
        state.SkipWithError("no frame");
        return;
      }
      const Frame& frame = **f;
      const auto r = s.keyer->frame(frame.image.view(), s.mask);
      const double t2 = thread_cpu();
      keyed += r.step == keyer::PlateKeyer::Step::kKeyed;
      encode_mask(s.mask, MaskCoding::kRowDelta, s.mask_bytes);
      const double t3 = thread_cpu();
      if (frames % 75 < 6) {  // 6 servers x 2 images per 25 frames: one JPEG per 12.5 frames
        cv::Mat rgb(frame.image.height(), frame.image.width(), CV_8UC3,
                    const_cast<Rgb8*>(frame.image.data()));
        cv::Mat bgr;
        cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
        cv::imencode(".jpg", bgr, s.jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
      }
      const double t4 = thread_cpu();
      render += t1 - t0;
      key += t2 - t1;
      code += t3 - t2;
      jpeg += t4 - t3;
      per_camera[c] += t4 - t0;
      benchmark::DoNotOptimize(s.mask_bytes.data());
      ++frames;
    }
  }
  if (keyed != frames) state.SkipWithError("a frame was not keyed");
  const double n = double(std::max<int64_t>(frames, 1));
  state.counters["render_ms"] = 1e3 * render / n;
  state.counters["key_ms"] = 1e3 * key / n;
  state.counters["code_ms"] = 1e3 * code / n;
  state.counters["jpeg_ms"] = 1e3 * jpeg / n;
  state.counters["total_ms"] = 1e3 * (render + key + code + jpeg) / n;
  for (std::size_t c = 0; c < servers.size(); ++c)
    state.counters["cam" + std::to_string(c) + "_ms"] = 1e3 * per_camera[c] / double(rounds);
  state.counters["x6_ms"] = 6e3 * (render + key + code + jpeg) / n;
}
BENCHMARK(BM_CaptureServerFrame)
    ->ArgName("reference")
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3);

// The same server's render with its caches cold, as in the demo where five other capture
// servers, the hull and the projector run between two of its frames: before every other render
// a 64 MB buffer (twice the L3) is read, evicting the camera's background (1.2 MB), noise table
// (2.2 MB), floor points and the previous image. Counters: warm_ms (renders right after a
// render of the same camera) and cold_ms (right after the eviction), thread CPU per render of
// one camera (cam1), interleaved so that load hits both alike; cold_over_warm their ratio.
void BM_RenderWarmVsCold(benchmark::State& state) {
  SimSourceOptions o;
  o.camera = sim::ring_cameras()[1];
  o.paced = false;
  auto source = SimFrameSource::create(o).value();
  if (!source->start()) state.SkipWithError("source start");
  std::vector<uint64_t> evict(std::size_t(64) << 17, 1);  // 64 MB
  uint64_t sink = 0;
  double warm = 0, cold = 0;
  int64_t n = 0;
  for (auto _ : state) {
    for (uint64_t& v : evict) sink += v++;
    double t0 = thread_cpu();
    auto a = source->next(std::chrono::milliseconds(1000));
    const double t1 = thread_cpu();
    auto b = source->next(std::chrono::milliseconds(1000));
    const double t2 = thread_cpu();
    if (!a || !*a || !b || !*b) {
      state.SkipWithError("no frame");
      return;
    }
    cold += t1 - t0;
    warm += t2 - t1;
    ++n;
  }
  benchmark::DoNotOptimize(sink);
  state.counters["warm_ms"] = 1e3 * warm / double(n);
  state.counters["cold_ms"] = 1e3 * cold / double(n);
  state.counters["cold_over_warm"] = cold / warm;
}
BENCHMARK(BM_RenderWarmVsCold)->Unit(benchmark::kMillisecond)->MinTime(3);

}  // namespace
}  // namespace studio::capture

BENCHMARK_MAIN();
