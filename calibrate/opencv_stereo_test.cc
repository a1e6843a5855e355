// Real images: the stereo chessboard pairs of Debian's opencv-doc package, calibrated by this
// library and by OpenCV's own stereoCalibrate on the same detections.
//
// Gauge: these pairs have no floor frame, so the free gauge applies: camera "left" (the first
// camera) is the studio frame, as in cv::stereoCalibrate, and the baseline is |centre of right|.
// Intrinsics model: OpenCV with k1, k2 (tangential and k3 fixed at 0) is the paper's rd3, rd5.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include <filesystem>
#include "calibrate/text.h"

#include "calibrate/camera_calibration.h"
#include "calibrate/detect.h"

namespace studio::calibrate {
namespace {

namespace fs = std::filesystem;
const char* kData = "/usr/share/doc/opencv-doc/examples/data";

TEST(OpenCvStereo, NoWorseThanStereoCalibrateOnTheSameDetections) {
  if (!fs::exists(fs::path(kData) / "left01.jpg")) GTEST_SKIP() << "opencv-doc is not installed";
  const fs::path dir = fs::path(STUDIO_BINARY_DIR) / "calibrate_opencv_stereo";
  fs::remove_all(dir);
  for (const char* side : {"left", "right"}) {
    fs::create_directories(dir / side);
    for (int i = 1; i <= 14; ++i) {
      const fs::path src = fs::path(kData) / format("{}{:02d}.jpg", side, i);
      if (fs::exists(src)) fs::create_symlink(src, dir / side / format("{:02d}.jpg", i));
    }
  }
  const TargetSpec target = *parse_target_spec("chessboard:9x6:0.025");
  auto detected = detect_directory(dir.string(), target);
  ASSERT_TRUE(detected) << detected.error().message;
  ASSERT_EQ(detected->cameras.size(), 2u);
  EXPECT_EQ(detected->cameras[0].width, 640);

  // Keep the pairs both cameras detected (cv::stereoCalibrate needs both).
  Observations obs = *detected;
  std::erase_if(obs.frames, [](const FrameObservations& f) { return f.views.size() != 2; });
  ASSERT_GE(obs.frames.size(), 10u);
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> left, right;
  const auto pts = target.points();
  for (const auto& f : obs.frames) {
    object.emplace_back();
    for (const auto& p : f.views[0].points)
      object.back().emplace_back(pts[p.id].x(), pts[p.id].y(), pts[p.id].z());
    for (auto* side : {&left, &right}) {
      const View& v = f.views[side == &left ? 0 : 1];
      side->emplace_back();
      for (const auto& p : v.points) side->back().emplace_back(p.pixel.x(), p.pixel.y());
    }
  }
  const cv::Size size(640, 480);
  const int model = cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3;
  cv::Mat k1, d1, k2, d2, r, t, e, fm, rv, tv;
  cv::calibrateCamera(object, left, size, k1, d1, rv, tv, model);
  cv::calibrateCamera(object, right, size, k2, d2, rv, tv, model);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-12);
  const double opencv_rms = cv::stereoCalibrate(object, left, right, k1, d1, k2, d2, size, r, t, e,
                                                fm, model | cv::CALIB_USE_INTRINSIC_GUESS, criteria);
  const double opencv_baseline = cv::norm(t);

  // 1. The tool as shipped: robust solve, outliers reported and dropped, RMS over the inliers.
  CalibrationOptions o;
  auto result = calibrate_cameras(obs, pts, o);
  ASSERT_TRUE(result) << result.error().message;
  const double baseline = result->cameras[1].centre_in_world().norm();
  // 2. The identical problem to OpenCV's: no outlier is dropped (plain least squares at the end).
  CalibrationOptions keep_all;
  keep_all.outlier_min_px = 1e9;
  auto same = calibrate_cameras(obs, pts, keep_all);
  ASSERT_TRUE(same) << same.error().message;
  ASSERT_TRUE(same->outliers.empty());
  const double same_baseline = same->cameras[1].centre_in_world().norm();
  std::printf("%zu pairs, %d observations. OpenCV stereoCalibrate: rms %.4f px, baseline %.5f m\n"
              "ours, outliers dropped: rms %.4f px over %d inliers (%zu outliers), baseline %.5f m "
              "(%+.3f %%), %.2f s\n"
              "ours, every observation: rms %.4f px, baseline %.5f m (%+.3f %%)\n",
              obs.frames.size(), result->observations + static_cast<int>(result->outliers.size()),
              opencv_rms, opencv_baseline, result->rms_px, result->observations,
              result->outliers.size(), baseline, 100 * (baseline / opencv_baseline - 1),
              result->seconds, same->rms_px, same_baseline,
              100 * (same_baseline / opencv_baseline - 1));
  std::printf("left f %.2f/%.2f c %.2f,%.2f k %.4f,%.4f | OpenCV f %.2f/%.2f c %.2f,%.2f k %.4f,%.4f\n",
              same->cameras[0].intrinsics.fx, same->cameras[0].intrinsics.fy,
              same->cameras[0].intrinsics.cx, same->cameras[0].intrinsics.cy,
              same->cameras[0].distortion.rd3, same->cameras[0].distortion.rd5,
              k1.at<double>(0, 0), k1.at<double>(1, 1), k1.at<double>(0, 2), k1.at<double>(1, 2),
              d1.at<double>(0), d1.at<double>(1));
  EXPECT_LE(result->rms_px, opencv_rms);
  EXPECT_NEAR(baseline / opencv_baseline, 1.0, 0.01);
  EXPECT_LE(same->rms_px, opencv_rms + 1e-4);
  EXPECT_NEAR(same_baseline / opencv_baseline, 1.0, 0.01);
}

}  // namespace
}  // namespace studio::calibrate
