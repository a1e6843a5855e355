#include "preview/camera_select.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace studio::preview {
namespace {

// Six cameras on a ring of radius 4 around the origin, 60 degrees apart, at actor height.
std::vector<StudioCameraPose> ring() {
  std::vector<StudioCameraPose> c;
  for (int i = 0; i < 6; ++i) {
    const double a = i * std::numbers::pi / 3;
    c.push_back({"cam" + std::to_string(i), {4 * std::sin(a), 1, 4 * std::cos(a)}});
  }
  return c;
}

Eigen::Vector3d at_azimuth(double deg) {
  const double a = deg * std::numbers::pi / 180;
  return {6 * std::sin(a), 1, 6 * std::cos(a)};
}

TEST(CameraSelect, ViewAngleAtTheTarget) {
  const Eigen::Vector3d t(0, 1, 0);
  EXPECT_NEAR(view_angle(at_azimuth(0), at_azimuth(90), t), std::numbers::pi / 2, 1e-12);
  EXPECT_NEAR(view_angle(at_azimuth(10), at_azimuth(10) * 0.5 + t * 0.5, t), 0, 1e-7);
  EXPECT_DOUBLE_EQ(view_angle(t, at_azimuth(0), t), std::numbers::pi);  // degenerate
}

TEST(CameraSelect, BlendThresholdIsTheNextCamerasAngle) {
  const Eigen::Vector3d t(0, 1, 0);
  // The eye at 10 degrees: cameras at 0, 60, 300 (= -60), 120, ... The 4th nearest is 120
  // degrees (110 from the eye); with two cameras the 3rd (-60: 70 degrees).
  const double deg = std::numbers::pi / 180;
  EXPECT_NEAR(blend_threshold(ring(), at_azimuth(10), t, {.cameras = 3}), 110 * deg, 1e-9);
  EXPECT_NEAR(blend_threshold(ring(), at_azimuth(10), t, {.cameras = 2}), 70 * deg, 1e-9);
  // At most k cameras: pi.
  auto few = ring();
  few.resize(3);
  EXPECT_DOUBLE_EQ(blend_threshold(few, at_azimuth(10), t, {.cameras = 3}), std::numbers::pi);
}

TEST(CameraSelect, NearestIsTheSmallestAngleNotTheClosestCamera) {
  auto cams = ring();
  cams[2].centre *= 0.3;  // cam2 much closer to the target, same direction (120 degrees)
  const Eigen::Vector3d t(0, 1, 0);
  // The eye at 50 degrees: cam1 (60) is 10 degrees away; cam0 (0) is 50.
  const auto n = nearest(cams, at_azimuth(50), t);
  ASSERT_EQ(n.size(), 1u);
  EXPECT_EQ(n[0].index, 1);
  EXPECT_DOUBLE_EQ(n[0].weight, 1);
  EXPECT_TRUE(nearest({}, at_azimuth(0), t).empty());
}

TEST(CameraSelect, BlendWeightsFollowTheUlrPenalty) {
  const auto cams = ring();
  const Eigen::Vector3d t(0, 1, 0);
  const auto b = blend(cams, at_azimuth(20), t, {.cameras = 2});
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[0].index, 0);  // 20 degrees
  EXPECT_EQ(b[1].index, 1);  // 40 degrees; threshold = cam5 at 80 degrees
  const double w0 = (1 - 20.0 / 80) / 20, w1 = (1 - 40.0 / 80) / 40;
  EXPECT_NEAR(b[0].weight, w0 / (w0 + w1), 1e-9);
  EXPECT_NEAR(b[1].weight, w1 / (w0 + w1), 1e-9);
  EXPECT_NEAR(b[0].weight + b[1].weight, 1, 1e-12);
}

TEST(CameraSelect, BlendIsContinuousAndExactAtACamera) {
  const auto cams = ring();
  const Eigen::Vector3d t(0, 1, 0);
  const auto at_cam = blend(cams, at_azimuth(60), t);
  ASSERT_EQ(at_cam.size(), 1u);
  EXPECT_EQ(at_cam[0].index, 1);
  // Moving the eye by a hundredth of a degree changes the weights by little.
  const auto a = blend(cams, at_azimuth(29.99), t), b = blend(cams, at_azimuth(30.01), t);
  double wa0 = 0, wb0 = 0;
  for (const auto& w : a) wa0 += w.index == 0 ? w.weight : 0;
  for (const auto& w : b) wb0 += w.index == 0 ? w.weight : 0;
  EXPECT_NEAR(wa0, wb0, 1e-3);
}

TEST(CameraSelect, OptionsAreValidated) {
  EXPECT_FALSE(BlendOptions{.cameras = 0}.validate());
  EXPECT_FALSE(BlendOptions{.cameras = 9}.validate());
  EXPECT_TRUE(BlendOptions{.cameras = 3}.validate());
}

}  // namespace
}  // namespace studio::preview
