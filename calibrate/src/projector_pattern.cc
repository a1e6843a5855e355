// The projected ChArUco pattern, its detection in the studio cameras and the surfaces of its
// features (calibrate/projector_pattern.h).
#include "calibrate/projector_pattern.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "calibrate/detect.h"

namespace studio::calibrate {

Expected<void> ProjectedPattern::validate(int width, int height) const {
  if (board.kind != TargetSpec::Kind::charuco) return fail("pattern: must be a charuco board");
  if (auto ok = board.validate(); !ok) return ok;
  const int s = square_px();
  if (s < 8 || std::abs(board.spacing - s) > 1e-9 || board.marker < 4 ||
      std::abs(board.marker - std::round(board.marker)) > 1e-9 || board.marker >= board.spacing)
    return fail(
        "pattern: square and marker sizes must be whole projector pixels, square >= 8, 4 <= marker "
        "< square");
  if (margin_px < 0) return fail("pattern: negative margin");
  if (x0 - margin_px < 0 || y0 - margin_px < 0 || x0 + board.cols * s + margin_px > width ||
      y0 + board.rows * s + margin_px > height)
    return fail("pattern: board of " + std::to_string(board.cols * s) + "x" +
                std::to_string(board.rows * s) + " px at (" + std::to_string(x0) + ", " +
                std::to_string(y0) + ") with margin " + std::to_string(margin_px) +
                " does not fit the " + std::to_string(width) + "x" + std::to_string(height) +
                " projector frame");
  return {};
}

Eigen::Vector2d ProjectedPattern::projector_pixel(int id) const {
  const int per_row = board.cols - 1;
  const int c = id % per_row, r = id / per_row;
  const double s = square_px();
  return {x0 + (c + 1) * s - 0.5, y0 + (r + 1) * s - 0.5};
}

Expected<cv::Mat> draw_pattern(const ProjectedPattern& pattern, int width, int height) {
  if (auto ok = pattern.validate(width, height); !ok) return std::unexpected(ok.error());
  const int s = pattern.square_px(), m = pattern.margin_px;
  cv::Mat frame(height, width, CV_8UC1, cv::Scalar(0));
  try {
    const auto dict = cv::aruco::getPredefinedDictionary(pattern.board.dictionary);
    const auto board = cv::aruco::CharucoBoard::create(
        pattern.board.cols, pattern.board.rows, static_cast<float>(s),
        static_cast<float>(pattern.board.marker), dict);
    cv::Mat img;
    board->draw(cv::Size(pattern.board.cols * s + 2 * m, pattern.board.rows * s + 2 * m), img, m,
                1);
    img.copyTo(frame(cv::Rect(pattern.x0 - m, pattern.y0 - m, img.cols, img.rows)));
  } catch (const cv::Exception& e) {
    return fail(std::string("pattern: OpenCV: ") + e.what());
  }
  return frame;
}

Expected<std::vector<PatternFeature>> capture_features(const std::vector<Camera>& cameras,
                                                       const PatternCapture& capture,
                                                       const ProjectedPattern& pattern,
                                                       std::vector<int>* detected) {
  if (capture.images.size() != cameras.size())
    return fail("capture " + capture.name + ": " + std::to_string(capture.images.size()) +
                " images for " + std::to_string(cameras.size()) + " cameras");
  std::map<int, PatternFeature> by_id;
  if (detected) detected->assign(cameras.size(), 0);
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const cv::Mat& image = capture.images[c];
    if (image.empty()) continue;
    if (image.cols != cameras[c].width || image.rows != cameras[c].height)
      return fail("capture " + capture.name + ": image of " + cameras[c].id + " is " +
                  std::to_string(image.cols) + "x" + std::to_string(image.rows) + ", the camera " +
                  std::to_string(cameras[c].width) + "x" + std::to_string(cameras[c].height));
    auto points = detect_target(image, pattern.board);
    if (!points)
      return fail("capture " + capture.name + ", " + cameras[c].id + ": " + points.error().message);
    if (detected) (*detected)[c] = static_cast<int>(points->size());
    for (const PointObservation& p : *points) {
      PatternFeature& f = by_id[p.id];
      f.projector_pixel = pattern.projector_pixel(p.id);
      f.views.push_back({static_cast<int>(c), p.pixel});
    }
  }
  std::vector<PatternFeature> out;
  for (auto& [id, f] : by_id)
    if (f.views.size() >= 2) out.push_back(std::move(f));
  return out;
}

int label_screen(const std::vector<Camera>& cameras, std::vector<PatternFeature>* features,
                 int screen, int other, double tolerance_m) {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> index;  // feature of each point
  for (std::size_t i = 0; i < features->size(); ++i) {
    (*features)[i].surface = other;
    if (auto x = triangulate_dlt(cameras, (*features)[i].views)) {
      points.push_back(*x);
      index.push_back(static_cast<int>(i));
    }
  }
  if (points.size() < 3) return 0;
  auto inliers_of = [&](const Plane& p) {
    std::vector<int> in;
    for (std::size_t k = 0; k < points.size(); ++k)
      if (std::abs(p.distance(points[k])) <= tolerance_m) in.push_back(static_cast<int>(k));
    return in;
  };
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  std::vector<int> best;
  for (int it = 0; it < 400; ++it) {
    const Eigen::Vector3d& a = points[pick(rng)];
    const Eigen::Vector3d& b = points[pick(rng)];
    const Eigen::Vector3d& c = points[pick(rng)];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-6) continue;
    Plane p;
    p.normal = n.normalized();
    p.offset = p.normal.dot(a);
    auto in = inliers_of(p);
    if (in.size() > best.size()) best = std::move(in);
  }
  if (best.size() >= 3) {
    std::vector<Eigen::Vector3d> sel;
    for (int k : best) sel.push_back(points[k]);
    if (auto refit = fit_plane(sel)) best = inliers_of(*refit);
  }
  for (int k : best) (*features)[index[k]].surface = screen;
  return static_cast<int>(best.size());
}

Expected<PatternCalibration> calibrate_projector_from_captures(
    const std::vector<Camera>& cameras, const std::vector<PatternCapture>& captures,
    const ProjectedPattern& pattern, ProjectorCalibrationOptions options) {
  if (auto ok = pattern.validate(options.width, options.height); !ok)
    return std::unexpected(ok.error());
  PatternCalibration out;
  std::vector<PatternFeature> all;
  options.screen_surface = 0;
  int boards = 0;
  for (const PatternCapture& capture : captures) {
    CaptureReport report;
    report.name = capture.name;
    auto features = capture_features(cameras, capture, pattern, &report.detected);
    if (!features) return std::unexpected(features.error());
    report.features = static_cast<int>(features->size());
    if (capture.board) {
      for (PatternFeature& f : *features) f.surface = 2 + boards;
      ++boards;
    } else {
      report.screen = label_screen(cameras, &*features, 0, 1);
    }
    all.insert(all.end(), features->begin(), features->end());
    out.captures.push_back(report);
  }
  auto result = calibrate_projector(cameras, all, options);
  if (!result) return std::unexpected(result.error());
  out.result = std::move(*result);
  return out;
}

}  // namespace studio::calibrate
