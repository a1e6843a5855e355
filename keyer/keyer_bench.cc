// Keyer and mask codec benchmarks (numbers go to BENCHMARKS.md, "Keyer and mask codec").
//
// Baselines run in this binary, so the ratios survive a noisy machine:
//  - the reference keyer (keyer/reference_keyer.h: per-pixel float formulas into a full image,
//    then runs, clean-up and encoding as in the fast path);
//  - FFmpeg's chromakey filter on the same raw frames (Debian's ffmpeg, one thread,
//    -f rawvideo rgb24 in, -f null out), timed as the CPU-time difference between a long and a
//    short run so process start-up does not count.
// fps counters are per CPU second (Google Benchmark's rates use CPU time): on this shared 2-core
// machine wall time mostly measures the other processes.
// Counters: fps (frames per second on one core), x_reference, x_ffmpeg (our speed over theirs),
// bytes (mean encoded mask size).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "core/mask_codec.h"
#ifdef STUDIO_KEYER_BENCH_SIM
#include "sim/cameras.h"
#include "sim/studio.h"
#endif
#include "keyer/keyer.h"
#include "keyer/reference_keyer.h"
#include "test_frames.h"

namespace fs = std::filesystem;
using namespace studio;
using namespace studio::keyer;

namespace {

constexpr int kFrames = 4;

const std::vector<testing::SyntheticFrame>& frames(int w, int h) {
  static std::map<std::pair<int, int>, std::vector<testing::SyntheticFrame>> cache;
  auto& v = cache[{w, h}];
  if (v.empty())
    for (int i = 0; i < kFrames; ++i) v.push_back(testing::make_frame(w, h, 0.6 * i, false, 3.0, 1 + i));
  return v;
}

std::map<std::pair<int, int>, double> ffmpeg_fps;


void BM_ReferenceKeyer(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1));
  const auto& fs_ = frames(w, h);
  KeyerOptions o;
  CleanupScratch scratch;
  RunMask clean;
  std::vector<uint8_t> bytes;
  std::size_t i = 0;
  for (auto _ : state) {
    const Mask m = reference_key(fs_[i++ % kFrames].image.view(), o);
    const RunMask raw = RunMask::from_mask(m.view());
    clean_mask(raw, o.cleanup, clean, scratch);
    encode_mask(clean, MaskCoding::kRowDelta, bytes);
    benchmark::DoNotOptimize(bytes.data());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

double thread_cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

double children_cpu_seconds() {
  rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// CPU seconds (user + system, all its threads) of one ffmpeg run over `loops` passes of the raw
// file; CPU time rather than wall time, because this machine is shared.
double run_ffmpeg(const std::string& raw, int w, int h, int loops) {
  const std::string cmd = "ffmpeg -hide_banner -loglevel error -nostdin -filter_threads 1 -threads 1 "
                          "-f rawvideo -pix_fmt rgb24 -s " + std::to_string(w) + "x" + std::to_string(h) +
                          " -stream_loop " + std::to_string(loops - 1) + " -i " + raw +
                          " -vf chromakey=0x0000ff:0.1:0.0 -threads 1 -f null - >/dev/null 2>&1";
  const double t0 = children_cpu_seconds();
  const int rc = std::system(cmd.c_str());
  const double s = children_cpu_seconds() - t0;
  return rc == 0 ? s : -1.0;
}

void BM_FFmpegChromakey(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1));
  if (std::system("ffmpeg -hide_banner -version >/dev/null 2>&1") != 0) {
    state.SkipWithError("ffmpeg not installed");
    return;
  }
  const fs::path raw = fs::temp_directory_path() / ("keyer_bench_" + std::to_string(::getpid()) + ".rgb");
  {
    std::ofstream out(raw, std::ios::binary);
    for (const auto& f : frames(w, h))
      out.write(reinterpret_cast<const char*>(f.image.data()), std::streamsize(f.image.pixels().size() * 3));
  }
  const int long_loops = w * h > 1000000 ? 25 : 100;
  double per_frame = 0;
  for (auto _ : state) {
    const double t_short = run_ffmpeg(raw.string(), w, h, 1);
    const double t_long = run_ffmpeg(raw.string(), w, h, long_loops);
    if (t_short < 0 || t_long < 0) {
      state.SkipWithError("ffmpeg chromakey failed");
      break;
    }
    per_frame = (t_long - t_short) / double((long_loops - 1) * kFrames);
    state.SetIterationTime(per_frame);
  }
  fs::remove(raw);
  if (per_frame > 0) {
    ffmpeg_fps[{w, h}] = 1.0 / per_frame;
    state.counters["fps"] = 1.0 / per_frame;
  }
}

void BM_Keyer(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1));
  const KeyMode mode = KeyMode(state.range(2));
  const auto& fs_ = frames(w, h);
  KeyerOptions o;
  o.mode = mode;
  auto keyer = Keyer::create(o);
  if (mode == KeyMode::kDifference) {
    Image<Rgb8> plate(w, h);  // the backing without the actor
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double shade = 0.8 + 0.3 * double(x) / w - 0.1 * double(y) / h;
        plate(x, y) = Rgb8{uint8_t(35 * shade), uint8_t(75 * shade), uint8_t(205 * shade)};
      }
    (void)keyer->capture_plate(plate.view());
  }
  RunMask mask;
  std::vector<uint8_t> bytes;
  double total_bytes = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    (void)keyer->key(fs_[i++ % kFrames].image.view(), mask);
    encode_mask(mask, MaskCoding::kRowDelta, bytes);
    total_bytes += double(bytes.size());
  }
  const double n = double(state.iterations());
  state.counters["fps"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["bytes"] = total_bytes / n;
  state.SetLabel(std::string(key_mode_name(mode)) + " kernel=" + Keyer::kernel_name());
}

// The ratios: the keyer and the reference keyer timed frame by frame, interleaved, in thread CPU
// time (this machine is shared; CPU time is what one core spends), against FFmpeg's CPU time.
void BM_KeyerRatios(benchmark::State& state) {
  const int w = int(state.range(0)), h = int(state.range(1));
  const auto& fs_ = frames(w, h);
  auto keyer = Keyer::create({});
  KeyerOptions o;
  CleanupScratch scratch;
  RunMask mask, clean;
  std::vector<uint8_t> bytes;
  double fast_s = 0, ref_s = 0;
  int n = 0;
  for (auto _ : state) {
    const auto& im = fs_[n++ % kFrames].image;
    const double t0 = thread_cpu_seconds();
    (void)keyer->key(im.view(), mask);
    encode_mask(mask, MaskCoding::kRowDelta, bytes);
    const double t1 = thread_cpu_seconds();
    const Mask m = reference_key(im.view(), o);
    clean_mask(RunMask::from_mask(m.view()), o.cleanup, clean, scratch);
    encode_mask(clean, MaskCoding::kRowDelta, bytes);
    const double t2 = thread_cpu_seconds();
    fast_s += t1 - t0;
    ref_s += t2 - t1;
  }
  const double fps = n / fast_s;
  state.counters["fps"] = fps;
  state.counters["reference_fps"] = n / ref_s;
  state.counters["x_reference"] = ref_s / fast_s;
  if (auto it = ffmpeg_fps.find({w, h}); it != ffmpeg_fps.end()) {
    state.counters["ffmpeg_fps"] = it->second;
    state.counters["x_ffmpeg"] = fps / it->second;
  }
}

void BM_MaskEncode(benchmark::State& state) {
  const MaskCoding coding = MaskCoding(state.range(0));
  auto keyer = Keyer::create({});
  RunMask mask;
  (void)keyer->key(frames(704, 576)[1].image.view(), mask);
  std::vector<uint8_t> bytes;
  for (auto _ : state) {
    encode_mask(mask, coding, bytes);
    benchmark::DoNotOptimize(bytes.data());
  }
  state.counters["bytes"] = double(bytes.size());
  state.SetLabel(coding == MaskCoding::kRuns ? "runs+varints" : "row-delta");
}

void BM_MaskDecode(benchmark::State& state) {
  const MaskCoding coding = MaskCoding(state.range(0));
  auto keyer = Keyer::create({});
  RunMask mask, out;
  (void)keyer->key(frames(704, 576)[1].image.view(), mask);
  const auto bytes = encode_mask(mask, coding);
  for (auto _ : state) {
    if (!decode_mask(bytes, out)) state.SkipWithError("decode failed");
    benchmark::DoNotOptimize(out.runs().data());
  }
  state.counters["bytes"] = double(bytes.size());
  state.SetLabel(coding == MaskCoding::kRuns ? "runs+varints" : "row-delta");
}

// Mean encoded size of the Middlebury dino masks (difference key against the black background).
void BM_DinoMaskBytes(benchmark::State& state) {
  const fs::path dir = fs::path(STUDIO_SHARED_DATA) / "middlebury_dino";
  KeyerOptions o;
  o.mode = KeyMode::kDifference;
  o.diff_low = 20;
  o.diff_high = 40;
  o.cleanup = {200, 3000};
  // A black background: the dino's dark parts match the plate, so a hole showing "clean
  // backing" is not evidence of a real gap here; fill holes by area only.
  o.cleanup.keep_backing_gaps = false;
  auto keyer = Keyer::create(o);
  std::vector<Image<Rgb8>> views;
  for (int i = 1; i <= 16; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "dinoSR%04d.png", i);
    cv::Mat bgr = cv::imread((dir / name).string(), cv::IMREAD_COLOR);
    if (bgr.empty()) break;
    Image<Rgb8> im(bgr.cols, bgr.rows);
    cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, im.data());
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    views.push_back(std::move(im));
  }
  if (views.empty()) {
    state.SkipWithError("../shared/data/middlebury_dino not found");
    return;
  }
  (void)keyer->capture_plate(Image<Rgb8>(views[0].width(), views[0].height(), Rgb8{0, 0, 0}).view());
  RunMask mask;
  double delta = 0, runs = 0;
  for (auto _ : state) {
    delta = runs = 0;
    for (const auto& v : views) {
      (void)keyer->key(v.view(), mask);
      delta += double(encode_mask(mask, MaskCoding::kRowDelta).size());
      runs += double(encode_mask(mask, MaskCoding::kRuns).size());
    }
  }
  state.counters["bytes"] = delta / double(views.size());
  state.counters["bytes_plain_runs"] = runs / double(views.size());
}

#ifdef STUDIO_KEYER_BENCH_SIM
// The simulated studio (6 cameras, 704x576, every realism knob on incl. motion blur and the
// projected picture): keying speed on its frames and the mean encoded size of the masks.
void BM_SimulatedStudio(benchmark::State& state) {
  sim::StudioOptions so;
  so.motion_blur = true;
  so.projected_image = true;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
  if (!studio) {
    state.SkipWithError(studio.error().message.c_str());
    return;
  }
  std::vector<Image<Rgb8>> images, all;
  std::vector<Mask> truths;
  for (int64_t frame = 0; frame < 200; frame += 25) {
    studio->render_all(frame, &images, &truths);
    all.insert(all.end(), images.begin(), images.end());  // copies: a moved-from Image keeps its size
  }
  auto keyer = Keyer::create({});
  RunMask mask;
  std::vector<uint8_t> bytes;
  double total_runs = 0, total_delta = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    (void)keyer->key(all[i++ % all.size()].view(), mask);
    encode_mask(mask, MaskCoding::kRowDelta, bytes);
  }
  for (const auto& im : all) {
    (void)keyer->key(im.view(), mask);
    total_delta += double(encode_mask(mask, MaskCoding::kRowDelta).size());
    total_runs += double(encode_mask(mask, MaskCoding::kRuns).size());
  }
  state.counters["fps"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["bytes"] = total_delta / double(all.size());
  state.counters["bytes_plain_runs"] = total_runs / double(all.size());
  state.SetLabel(std::to_string(all.size()) + " masks");
}
BENCHMARK(BM_SimulatedStudio)->Unit(benchmark::kMicrosecond);
#endif

}  // namespace

BENCHMARK(BM_ReferenceKeyer)->Args({1920, 1080})->Args({704, 576})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FFmpegChromakey)->Args({1920, 1080})->Args({704, 576})->UseManualTime()->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Keyer)
    ->Args({1920, 1080, int(KeyMode::kBlue)})
    ->Args({704, 576, int(KeyMode::kBlue)})
    ->Args({1920, 1080, int(KeyMode::kDifference)})
    ->Args({704, 576, int(KeyMode::kDifference)})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KeyerRatios)->Args({1920, 1080})->Args({704, 576})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MaskEncode)->Arg(int(MaskCoding::kRuns))->Arg(int(MaskCoding::kRowDelta));
BENCHMARK(BM_MaskDecode)->Arg(int(MaskCoding::kRuns))->Arg(int(MaskCoding::kRowDelta));
BENCHMARK(BM_DinoMaskBytes)->Iterations(1)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
