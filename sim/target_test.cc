// Calibration targets rendered into virtual cameras: OpenCV's detectors find the corners where
// the pose says they are (sub-pixel realistic rendering).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "sim/cameras.h"
#include "sim/target.h"

namespace studio::sim {
namespace {

cv::Mat grey(const Image<Rgb8>& img) {
  cv::Mat rgb(img.height(), img.width(), CV_8UC3, const_cast<Rgb8*>(img.data())), g;
  cv::cvtColor(rgb, g, cv::COLOR_RGB2GRAY);
  return g;
}

// The board about `distance` in front of the camera, tilted, centred on the optical axis.
Rigid3 pose_in_front(const Camera& cam, const TargetSpec& spec, double distance, double yaw,
                     double pitch, double roll) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()));
  const Eigen::Vector3d half(spec.squares_x * spec.square / 2, spec.squares_y * spec.square / 2, 0);
  const Rigid3 cam_from_target(q, Eigen::Vector3d(0, 0, distance) - (q * half));
  return cam.cam_from_world.inverse() * cam_from_target;
}

struct Case {
  double distance, yaw, pitch, roll;
};

void check_chessboard(const Camera& cam, const TargetSpec& spec, const Case& c, double* worst,
                      double* rms_sum, int* count) {
  const Target target = Target::create(spec).value();
  const Rigid3 pose = pose_in_front(cam, spec, c.distance, c.yaw, c.pitch, c.roll);
  Image<Rgb8> img;
  target.render(cam, pose, {}, &img);
  std::vector<Eigen::Vector2d> truth;
  std::vector<bool> visible;
  target.project_corners(cam, pose, &truth, &visible);
  for (bool v : visible) ASSERT_TRUE(v);
  std::vector<cv::Point2f> found;
  const cv::Size pattern(spec.squares_x - 1, spec.squares_y - 1);
  ASSERT_TRUE(cv::findChessboardCornersSB(grey(img), pattern, found,
                                          cv::CALIB_CB_ACCURACY | cv::CALIB_CB_NORMALIZE_IMAGE))
      << "distance " << c.distance << " yaw " << c.yaw;
  ASSERT_EQ(found.size(), truth.size());
  cv::cornerSubPix(grey(img), found, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  // The detector may start from another corner of the board: match each detection to the
  // nearest true corner (corners are > 10 px apart, errors are < 1 px).
  Eigen::Vector2d bias = Eigen::Vector2d::Zero();
  for (const cv::Point2f& p : found) {
    double best = 1e9;
    Eigen::Vector2d off;
    for (const Eigen::Vector2d& t : truth) {
      const double d = std::hypot(p.x - t.x(), p.y - t.y());
      if (d < best) {
        best = d;
        off = Eigen::Vector2d(p.x, p.y) - t;
      }
    }
    bias += off / found.size();
    *worst = std::max(*worst, best);
    *rms_sum += best * best;
    ++*count;
  }
  std::cout << "  case distance " << c.distance << ": mean offset " << bias.transpose() << " px\n";
}

TEST(SimTarget, ChessboardCornersDetectedWhereThePoseSays) {
  const std::vector<Camera> cams = ring_cameras({.count = 2});
  TargetSpec spec;
  spec.squares_x = 9;
  spec.squares_y = 7;
  double worst = 0, rms = 0;
  int n = 0;
  for (const Case& c : {Case{2.2, 0.0, 0.0, 0.0}, Case{2.6, 0.5, 0.2, 0.1}, Case{3.0, -0.4, -0.3, -0.2},
                        Case{2.0, 0.2, 0.45, 0.7}}) {
    check_chessboard(cams[0], spec, c, &worst, &rms, &n);
  }
  check_chessboard(cams[1], spec, {2.4, 0.3, -0.2, 0.3}, &worst, &rms, &n);
  rms = std::sqrt(rms / n);
  RecordProperty("worst_px", std::to_string(worst));
  RecordProperty("rms_px", std::to_string(rms));
  std::cout << "chessboard: " << n << " corners, rms " << rms << " px, worst " << worst << " px\n";
  EXPECT_LT(worst, 0.3);
  EXPECT_LT(rms, 0.1);
}

TEST(SimTarget, ChessboardWithRadialDistortion) {
  Camera cam = ring_cameras({.count = 1})[0];
  cam.distortion = Distortion::radial(-0.15, 0.04);
  TargetSpec spec;
  spec.squares_x = 8;
  spec.squares_y = 6;
  spec.square = 0.12;
  double worst = 0, rms = 0;
  int n = 0;
  check_chessboard(cam, spec, {2.3, 0.3, 0.1, 0.05}, &worst, &rms, &n);
  EXPECT_LT(worst, 0.3);
}

TEST(SimTarget, CharucoCornersCarryTheRightIds) {
  const Camera cam = ring_cameras({.count = 1})[0];
  TargetSpec spec;
  spec.kind = TargetSpec::Kind::charuco;
  spec.squares_x = 7;
  spec.squares_y = 5;
  spec.square = 0.16;
  spec.marker = 0.12;
  spec.dictionary = cv::aruco::DICT_4X4_50;
  const Target target = Target::create(spec).value();
  ASSERT_EQ(target.markers().size(), 17u);
  const Rigid3 pose = pose_in_front(cam, spec, 2.2, 0.35, -0.2, 0.1);
  Image<Rgb8> img;
  target.render(cam, pose, {}, &img);
  std::vector<Eigen::Vector2d> truth;
  std::vector<bool> visible;
  target.project_corners(cam, pose, &truth, &visible);

  const cv::Mat g = grey(img);
  const auto dict = cv::aruco::getPredefinedDictionary(spec.dictionary);
  const auto board = cv::aruco::CharucoBoard::create(spec.squares_x, spec.squares_y, float(spec.square),
                                                     float(spec.marker), dict);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(g, dict, marker_corners, marker_ids);
  EXPECT_EQ(marker_ids.size(), target.markers().size());
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  ASSERT_FALSE(marker_ids.empty());
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, g, board, corners, ids);
  ASSERT_EQ(static_cast<int>(ids.size()), spec.corner_count());
  cv::cornerSubPix(g, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
  double worst = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const Eigen::Vector2d& t = truth[ids[i]];
    worst = std::max(worst, std::hypot(corners[i].x - t.x(), corners[i].y - t.y()));
  }
  std::cout << "charuco: " << ids.size() << " corners, worst " << worst << " px\n";
  EXPECT_LT(worst, 0.3);
}

TEST(SimTarget, BackOfTheBoardAndBadSpecs) {
  const Camera cam = ring_cameras({.count = 1})[0];
  TargetSpec spec;
  const Target target = Target::create(spec).value();
  // Turned around: corners are not visible.
  const Rigid3 pose = pose_in_front(cam, spec, 2.5, 3.14159, 0, 0);
  std::vector<Eigen::Vector2d> px;
  std::vector<bool> visible;
  target.project_corners(cam, pose, &px, &visible);
  for (bool v : visible) EXPECT_FALSE(v);
  TargetSpec bad = spec;
  bad.squares_x = 2;
  EXPECT_FALSE(Target::create(bad));
  bad = spec;
  bad.kind = TargetSpec::Kind::charuco;
  bad.marker = 0.2;
  EXPECT_FALSE(Target::create(bad));
  bad.marker = 0.07;
  bad.dictionary = 0;  // DICT_4X4_50 has 50 markers; 11x11 squares need 60
  auto r = Target::create(bad);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace studio::sim
