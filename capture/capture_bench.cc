// Recorder headroom (issue 3 item 5): how fast a 704x576 RGB take reaches the disk, against the
// 25 fps a capture server needs. Numbers go to BENCHMARKS.md, "Capture".
//
// Benchmarks (wall time: the disk is the resource, not the CPU):
//  - BM_PlainWrite (baseline): the same payloads written with plain write() in the calling
//    thread, no header, no CRC, fdatasync at the end: the disk/page-cache rate itself;
//  - BM_RecorderTake: the Recorder (pooled queue, writer thread, CRC-32, writev + index append,
//    fdatasync, index and take.yaml at the end) fed as fast as push() accepts;
//  - BM_Crc32: the checksum alone, per frame.
// Counters: fps (frames per second), headroom (fps / 25), x_plain (recorder rate / baseline rate),
// MBps. Takes go to $STUDIO_BENCH_TAKES (default: <build>/capture_bench_takes, i.e. the disk the
// build tree is on) and are deleted after each run.
#include <benchmark/benchmark.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "capture/crc32.h"
#include "capture/recorder.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::capture;

namespace {

constexpr int kW = 704, kH = 576, kFramesPerTake = 50;
double g_plain_fps = 0;

fs::path bench_dir() {
  const char* env = std::getenv("STUDIO_BENCH_TAKES");
  fs::path d = env ? fs::path(env) : fs::path(STUDIO_BINARY_DIR) / "capture_bench_takes";
  fs::create_directories(d);
  return d / ("run_" + std::to_string(::getpid()));
}

Image<Rgb8> frame_image() {
  Image<Rgb8> img(kW, kH);
  uint32_t s = 1;
  for (auto& p : img.pixels()) {
    s = s * 1664525u + 1013904223u;
    p = Rgb8{uint8_t(s >> 24), uint8_t(s >> 16), uint8_t(s >> 8)};
  }
  return img;
}

void BM_PlainWrite(benchmark::State& state) {
  const auto img = frame_image();
  const fs::path dir = bench_dir();
  fs::create_directories(dir);
  const std::size_t bytes = img.pixels().size() * 3;
  int take = 0;
  for (auto _ : state) {
    const std::string path = (dir / ("plain" + std::to_string(take++))).string();
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
    for (int i = 0; i < kFramesPerTake; ++i)
      if (::write(fd, img.data(), bytes) != ssize_t(bytes)) state.SkipWithError("write failed");
    ::fdatasync(fd);
    ::close(fd);
    ::unlink(path.c_str());
  }
  fs::remove_all(dir);
  const double n = double(state.iterations()) * kFramesPerTake;
  state.counters["fps"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["MBps"] = benchmark::Counter(n * double(bytes) / 1e6, benchmark::Counter::kIsRate);
}

void BM_RecorderTake(benchmark::State& state) {
  const auto img = frame_image();
  const fs::path dir = bench_dir();
  uint64_t written = 0, drops = 0;
  int take = 0;
  for (auto _ : state) {
    TakeInfo info;
    info.take = "bench" + std::to_string(take);
    info.camera_id = "cam0";
    info.width = kW;
    info.height = kH;
    info.period_ns = 40'000'000;
    const std::string take_dir = (dir / info.take / "cam0").string();
    auto rec = Recorder::start({.dir = take_dir, .queue_frames = 8}, info);
    if (!rec) {
      state.SkipWithError(rec.error().message.c_str());
      return;
    }
    // Push every frame; when the queue is full, wait for the writer (counted retries would be
    // drops in a live take; here the point is the sustained write rate).
    for (int i = 0; i < kFramesPerTake; ++i)
      while (!(*rec)->push(uint64_t(i), 0, img.view())) ::usleep(200);
    (*rec)->stop();
    auto r = (*rec)->wait();
    if (!r) state.SkipWithError(r.error().message.c_str());
    written += (*rec)->stats().frames_written;
    drops += (*rec)->stats().queue_drops;
    fs::remove_all(dir / info.take);
    ++take;
  }
  fs::remove_all(dir);
  const double n = double(written);
  state.counters["fps"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["MBps"] = benchmark::Counter(n * (double(kW) * kH * 3 + kFrameHeaderSize) / 1e6,
                                              benchmark::Counter::kIsRate);
  // Rates are divided by wall time after the run; headroom / x_plain need the same division, so
  // they are computed from fps below via kIsRate counters scaled by constants.
  state.counters["headroom"] = benchmark::Counter(n / 25.0, benchmark::Counter::kIsRate);
  if (g_plain_fps > 0)
    state.counters["x_plain"] = benchmark::Counter(n / g_plain_fps, benchmark::Counter::kIsRate);
}

// Sustained recording (issue 17 item 5): one long take (250 frames = 10 s of one camera) through
// the recorder with its periodic fdatasync every state.range(0) ms, frames pushed as fast as the
// writer takes them: the disk rate a capture server can count on while takes are durable.
void BM_RecorderSustained(benchmark::State& state) {
  const auto img = frame_image();
  const fs::path dir = bench_dir();
  constexpr int kFrames = 250;
  uint64_t written = 0, syncs = 0;
  int take = 0;
  for (auto _ : state) {
    TakeInfo info;
    info.take = "sustained" + std::to_string(take++);
    info.camera_id = "cam0";
    info.width = kW;
    info.height = kH;
    info.period_ns = 40'000'000;
    auto rec = Recorder::start({.dir = (dir / info.take / "cam0").string(),
                                .queue_frames = 8,
                                .sync_interval_ms = int(state.range(0))},
                               info);
    if (!rec) {
      state.SkipWithError(rec.error().message.c_str());
      return;
    }
    for (int i = 0; i < kFrames; ++i)
      while (!(*rec)->push(uint64_t(i), 0, img.view())) ::usleep(200);
    (*rec)->stop();
    if (auto r = (*rec)->wait(); !r) state.SkipWithError(r.error().message.c_str());
    written += (*rec)->stats().frames_written;
    syncs += (*rec)->stats().syncs;
    fs::remove_all(dir / info.take);
  }
  fs::remove_all(dir);
  const double n = double(written);
  state.counters["fps"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["MBps"] = benchmark::Counter(n * (double(kW) * kH * 3 + kFrameHeaderSize) / 1e6,
                                              benchmark::Counter::kIsRate);
  state.counters["cameras_at_25fps"] = benchmark::Counter(n / 25.0, benchmark::Counter::kIsRate);
  state.counters["syncs_per_take"] = double(syncs) / double(std::max<int>(take, 1));
  if (g_plain_fps > 0)
    state.counters["x_plain"] = benchmark::Counter(n / g_plain_fps, benchmark::Counter::kIsRate);
}

void BM_Crc32(benchmark::State& state) {
  const auto img = frame_image();
  const std::size_t bytes = img.pixels().size() * 3;
  for (auto _ : state) benchmark::DoNotOptimize(crc32_update(0, img.data(), bytes));
  state.counters["fps"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["MBps"] = benchmark::Counter(double(state.iterations()) * double(bytes) / 1e6,
                                              benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_PlainWrite)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_RecorderTake)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(3.0);
BENCHMARK(BM_RecorderSustained)
    ->Arg(1000)
    ->Arg(200)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK(BM_Crc32)->Unit(benchmark::kMillisecond);

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // The baseline's rate, for x_plain: one short run before the registered benchmarks.
  {
    const auto img = frame_image();
    const fs::path dir = bench_dir();
    fs::create_directories(dir);
    const std::string path = (dir / "calibrate").string();
    const std::size_t bytes = img.pixels().size() * 3;
    const auto t0 = std::chrono::steady_clock::now();
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
    for (int i = 0; i < kFramesPerTake * 2; ++i) (void)!::write(fd, img.data(), bytes);
    ::fdatasync(fd);
    ::close(fd);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    g_plain_fps = kFramesPerTake * 2 / s;
    fs::remove_all(dir);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
