#include "tracker/head_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace studio::tracker {
namespace {

constexpr int64_t kFrameNs = 40'000'000;  // 25 fps

HeadDetection detection(const Eigen::Vector3d& p, double confidence = 0.9) {
  HeadDetection d;
  d.position = p;
  d.confidence = confidence;
  return d;
}

HeadTracker tracker(HeadTrackerOptions o = {}) { return HeadTracker::create(o).value(); }

TEST(HeadTracker, FiltersNoiseAndEstimatesVelocity) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.01);
  auto t = tracker();
  const Eigen::Vector3d v(0.8, 0, -0.5);  // walking
  double raw2 = 0, filtered2 = 0, velocity2 = 0;
  int n = 0;
  for (int f = 0; f < 150; ++f) {
    const Eigen::Vector3d truth = Eigen::Vector3d(-1, 1.65, 0.5) + v * (f * 0.04);
    const Eigen::Vector3d z = truth + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const auto poses = t.update(std::array{detection(z)}, int64_t(f) * kFrameNs);
    ASSERT_EQ(poses.size(), 1u);
    EXPECT_EQ(poses[0].actor_id, 1u);
    if (f >= 50) {
      raw2 += (z - truth).squaredNorm();
      filtered2 += (poses[0].position - truth).squaredNorm();
      velocity2 += (poses[0].velocity - v).squaredNorm();
      ++n;
    }
  }
  EXPECT_LT(std::sqrt(filtered2 / n), 0.7 * std::sqrt(raw2 / n));
  EXPECT_LT(std::sqrt(velocity2 / n), 0.15);  // m/s RMS
}

TEST(HeadTracker, PredictionCompensatesLatency) {
  auto t = tracker();
  const Eigen::Vector3d v(1.0, 0, 0);
  HeadPose pose;
  for (int f = 0; f < 60; ++f)
    pose = t.update(std::array{detection(Eigen::Vector3d(0, 1.6, 0) + v * (f * 0.04))},
                    int64_t(f) * kFrameNs)[0];
  const int64_t display_ns = pose.capture_ns + 80'000'000;  // 80 ms later
  const Eigen::Vector3d truth = Eigen::Vector3d(0, 1.6, 0) + v * (59 * 0.04 + 0.08);
  EXPECT_LT((pose.predict(display_ns) - truth).norm(), 0.005);
  EXPECT_GT((pose.position - truth).norm(), 0.075);  // the stale pose would be 8 cm off
  // Extrapolation is bounded and never goes backwards.
  EXPECT_NEAR((pose.predict(pose.capture_ns + 5'000'000'000) - pose.position).norm(), 0.25, 0.01);
  EXPECT_EQ(pose.predict(pose.capture_ns - 1'000'000'000), pose.position);
}

TEST(HeadTracker, KeepsIdentitiesOfTwoActorsAndNumbersNewOnes) {
  auto t = tracker();
  for (int f = 0; f < 50; ++f) {
    const double s = f * 0.04;
    // Detections arrive in either order: identities follow positions.
    std::vector<HeadDetection> d = {detection({-1 + 0.5 * s, 1.7, 0}, 0.9),
                                    detection({1 - 0.5 * s, 1.6, 0.6}, 0.8)};
    if (f % 2) std::swap(d[0], d[1]);
    const auto poses = t.update(d, int64_t(f) * kFrameNs);
    ASSERT_EQ(poses.size(), 2u);
    for (const auto& p : poses) {
      if (p.actor_id == 1)
        EXPECT_NEAR(p.position.z(), 0, 0.02);
      else {
        EXPECT_EQ(p.actor_id, 2u);
        EXPECT_NEAR(p.position.z(), 0.6, 0.02);
      }
    }
  }
  // A third actor far away gets a new id.
  const auto poses = t.update(std::array{detection({-1.2, 1.7, -1.2})}, 50 * kFrameNs);
  bool third = false;
  for (const auto& p : poses) third |= p.actor_id == 3;
  EXPECT_TRUE(third);
}

TEST(HeadTracker, CoastsWithFallingConfidenceThenFallsBackSanely) {
  HeadTrackerOptions o;
  o.max_missed = 5;
  auto t = tracker(o);
  EXPECT_EQ(t.primary().confidence, 0);  // nothing yet: the rest position
  EXPECT_EQ(t.primary().position, o.rest_position);
  for (int f = 0; f < 20; ++f)
    t.update(std::array{detection({0.04 * f, 1.7, 0})}, int64_t(f) * kFrameNs);
  const Eigen::Vector3d last = t.primary().position;
  double confidence = t.primary().confidence;
  for (int f = 20; f < 25; ++f) {  // the actor left the volume: empty frames
    const auto poses = t.update({}, int64_t(f) * kFrameNs);
    ASSERT_EQ(poses.size(), 1u);
    EXPECT_LT(poses[0].confidence, confidence);
    confidence = poses[0].confidence;
    EXPECT_LT((poses[0].position - last).norm(), 0.2);
  }
  const auto gone = t.update({}, 25 * kFrameNs);
  EXPECT_TRUE(gone.empty());
  const HeadPose p = t.primary();
  EXPECT_EQ(p.confidence, 0);
  EXPECT_EQ(p.actor_id, 0u);
  EXPECT_TRUE(p.position.allFinite());
  EXPECT_LT((p.position - last).norm(), 0.2);
  EXPECT_EQ(p.capture_ns, 25 * kFrameNs);
  // It comes back as a new track.
  const auto back = t.update(std::array{detection({0, 1.7, 0})}, 26 * kFrameNs);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].actor_id, 2u);
}

TEST(HeadTracker, IgnoresFramesOutOfOrder) {
  auto t = tracker();
  t.update(std::array{detection({0, 1.7, 0})}, 10 * kFrameNs);
  const auto again = t.update(std::array{detection({1, 1.7, 0})}, 9 * kFrameNs);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].position, Eigen::Vector3d(0, 1.7, 0));
}

TEST(HeadTrackerOptions, RejectsNonsense) {
  HeadTrackerOptions o;
  o.gate = 0;
  EXPECT_FALSE(HeadTracker::create(o).has_value());
  o = {};
  o.coast_decay = 1.5;
  EXPECT_FALSE(o.validate());
  o = {};
  o.measurement_sigma = -1;
  EXPECT_FALSE(o.validate());
  EXPECT_TRUE(HeadTrackerOptions{}.validate());
}

}  // namespace
}  // namespace studio::tracker
