// One-stage calibration of the synthetic studio (8 cameras, 12 frames + 3 held-out,
// 100 points, 0.2 px noise) against the baseline in the same process: OpenCV's
// cv::calibrateCamera run once per camera on the same observations (k1, k2 only), which gives
// intrinsics but no common studio frame. Counter `vs_opencv_per_camera` = our time / baseline.
#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>

#include <chrono>

#include "calibrate/camera_calibration.h"
#include "calibrate/synthetic.h"

namespace studio::calibrate {
namespace {

const SyntheticStudio& studio() {
  static const SyntheticStudio s = make_synthetic_studio(SyntheticStudioOptions{});
  return s;
}

void opencv_per_camera(const SyntheticStudio& s) {
  for (const auto& cam : s.observations.cameras) {
    std::vector<std::vector<cv::Point3f>> object;
    std::vector<std::vector<cv::Point2f>> image;
    for (const auto& f : s.observations.frames) {
      if (f.holdout) continue;
      for (const auto& v : f.views) {
        if (v.camera_id != cam.id) continue;
        object.emplace_back();
        image.emplace_back();
        for (const auto& p : v.points) {
          const auto& x = s.target_points[p.id];
          object.back().emplace_back(x.x(), x.y(), x.z());
          image.back().emplace_back(p.pixel.x(), p.pixel.y());
        }
      }
    }
    cv::Mat k, d;
    std::vector<cv::Mat> r, t;
    cv::calibrateCamera(object, image, cv::Size(cam.width, cam.height), k, d, r, t,
                        cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3);
    benchmark::DoNotOptimize(k.data);
  }
}

double baseline_seconds() {
  static const double seconds = [] {
    opencv_per_camera(studio());  // warm up
    const int runs = 3;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < runs; ++i) opencv_per_camera(studio());
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / runs;
  }();
  return seconds;
}

void BM_OneStageCalibration_8cams_12frames(benchmark::State& state) {
  const SyntheticStudio& s = studio();
  const double baseline = baseline_seconds();
  CalibrationOptions o;
  double total = 0, rms = 0;
  int iterations = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    auto r = calibrate_cameras(s.observations, s.target_points, o);
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      return;
    }
    rms = r->rms_px;
    iterations = r->iterations;
  }
  state.counters["rms_px"] = rms;
  state.counters["ceres_iterations"] = iterations;
  state.counters["baseline_s"] = baseline;
  state.counters["vs_opencv_per_camera"] = total / state.iterations() / baseline;
}
BENCHMARK(BM_OneStageCalibration_8cams_12frames)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Baseline_OpenCvCalibrateCameraPerCamera(benchmark::State& state) {
  for (auto _ : state) opencv_per_camera(studio());
}
BENCHMARK(BM_Baseline_OpenCvCalibrateCameraPerCamera)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace studio::calibrate

BENCHMARK_MAIN();
