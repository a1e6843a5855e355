// Keyframe sampling (step, linear, slerp), play modes and the clock.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "scene/animation.h"

using namespace studio::scene;

namespace {

Track translation_track(Interpolation i) {
  Track t;
  t.node = "n";
  t.path = TrackPath::translation;
  t.interpolation = i;
  t.times = {0.0, 1.0, 3.0};
  t.values = {{0, 0, 0, 0}, {2, 0, 0, 0}, {2, 4, 0, 0}};
  return t;
}

}  // namespace

TEST(Track, LinearInterpolatesAndClampsOutsideTheKeys) {
  const Track t = translation_track(Interpolation::linear);
  EXPECT_TRUE(sample(t, -1).isApprox(Eigen::Vector4d(0, 0, 0, 0)));
  EXPECT_TRUE(sample(t, 0.25).isApprox(Eigen::Vector4d(0.5, 0, 0, 0)));
  EXPECT_TRUE(sample(t, 2.0).isApprox(Eigen::Vector4d(2, 2, 0, 0)));
  EXPECT_TRUE(sample(t, 5.0).isApprox(Eigen::Vector4d(2, 4, 0, 0)));
}

TEST(Track, StepHoldsTheEarlierKey) {
  const Track t = translation_track(Interpolation::step);
  EXPECT_EQ(sample(t, 0.99)[0], 0.0);
  EXPECT_EQ(sample(t, 1.0)[0], 2.0);
  EXPECT_EQ(sample(t, 2.99)[1], 0.0);
}

TEST(Track, BinarySearchAgreesWithLinearScan) {
  Track t;
  t.node = "n";
  for (int k = 0; k < 50; ++k) {
    t.times.push_back(k * 0.1 + (k % 3) * 0.01);
    t.values.push_back(Eigen::Vector4d(std::sin(k), k, -k, 0));
  }
  for (double x = -0.5; x < 6; x += 0.0137) EXPECT_EQ(sample(t, x), sample_linear_scan(t, x)) << x;
}

TEST(Track, RotationSlerpsOnTheShortestArc) {
  Track t;
  t.node = "n";
  t.path = TrackPath::rotation;
  t.times = {0, 1};
  const Eigen::Quaterniond a = Eigen::Quaterniond::Identity();
  // 170 degrees about y, stored with negative w: the shortest arc is still 85 degrees at u = .5.
  Eigen::Quaterniond b(Eigen::AngleAxisd(170.0 * std::numbers::pi / 180, Eigen::Vector3d::UnitY()));
  b.coeffs() *= -1;
  t.values = {a.coeffs(), b.coeffs()};
  const Eigen::Vector4d v = sample(t, 0.5);
  const Eigen::Quaterniond q(v[3], v[0], v[1], v[2]);
  EXPECT_NEAR(q.norm(), 1.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(q).angle() * 180 / std::numbers::pi, 85.0, 1e-9);
}

TEST(Track, ValidationRefusesBadKeys) {
  Track t = translation_track(Interpolation::linear);
  EXPECT_TRUE(t.validate());
  Track unsorted = t;
  unsorted.times[2] = 1.0;
  EXPECT_FALSE(unsorted.validate());
  Track nan = t;
  nan.values[1][0] = NAN;
  EXPECT_FALSE(nan.validate());
  Track mismatch = t;
  mismatch.values.pop_back();
  EXPECT_FALSE(mismatch.validate());
  Track zero_rotation = t;
  zero_rotation.path = TrackPath::rotation;
  EXPECT_FALSE(zero_rotation.validate());  // the first key (0,0,0,0) is not a quaternion
  Track empty;
  empty.node = "n";
  EXPECT_FALSE(empty.validate());
}

TEST(PlayModes, OnceLoopPingPong) {
  EXPECT_DOUBLE_EQ(animation_time(-1, 2, PlayMode::once), 0);
  EXPECT_DOUBLE_EQ(animation_time(1.5, 2, PlayMode::once), 1.5);
  EXPECT_DOUBLE_EQ(animation_time(7, 2, PlayMode::once), 2);
  EXPECT_DOUBLE_EQ(animation_time(5.5, 2, PlayMode::loop), 1.5);
  EXPECT_DOUBLE_EQ(animation_time(-0.5, 2, PlayMode::loop), 1.5);
  EXPECT_DOUBLE_EQ(animation_time(2.5, 2, PlayMode::ping_pong), 1.5);
  EXPECT_DOUBLE_EQ(animation_time(4.5, 2, PlayMode::ping_pong), 0.5);
  EXPECT_DOUBLE_EQ(animation_time(3, 0, PlayMode::loop), 0);
}

TEST(Clock, PlayingAdvancesWithFramesAndRestsBeforeItsAnchor) {
  AnimationClock c;
  c.playing = true;
  c.anchor_frame = 100;
  c.anchor_time = 1.0;
  c.speed = 2.0;
  EXPECT_DOUBLE_EQ(c.clock_time(90, 0.04), 1.0);  // started at a future frame: waits
  EXPECT_DOUBLE_EQ(c.clock_time(125, 0.04), 1.0 + 2.0 * 25 * 0.04);
  c.playing = false;
  EXPECT_DOUBLE_EQ(c.clock_time(125, 0.04), 1.0);
}
