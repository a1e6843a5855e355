// VelocityField (projector/velocity_field.h) and late latching's prediction: a new mesh moved
// forward by the PREVIOUS fit's velocities, looked up per vertex, and grown by the margin that
// counts those velocities' age (projector/mask_margin.h velocity_age_s), covers the true actor at
// display time; the same margin without the prediction does not. The scene: a hand on a 0.6 m
// arc at 1.5 m/s beside a still torso (mask_test.cc's swing), every mesh re-tessellated.
#include "projector/velocity_field.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "projector/mask_geometry.h"
#include "projector/mask_margin.h"
#include "testing/shapes.h"

namespace studio::projector {
namespace {

using testing::box;
using testing::coverage;
using testing::merge;
using testing::random_rotation;
using testing::sphere;

constexpr int64_t kFrameNs = 40'000'000;  // 25 fps
const Eigen::Vector3d kShoulder(0.25, 1.45, 0);
constexpr double kRadius = 0.6, kSpeed = 1.5;

Eigen::Vector3d hand_at(int64_t t_ns) {
  const double angle = -1.2 + kSpeed / kRadius * 1e-9 * double(t_ns);
  return kShoulder +
         kRadius * Eigen::Vector3d(0.3 * std::cos(angle), -std::cos(angle) * 0.95, std::sin(angle))
                       .normalized();
}

ActorMesh swing_at(int64_t t_ns, int frame, std::mt19937& rng) {
  ActorMesh m =
      merge(box(Eigen::Vector3d(-0.05, 1.2, 0), Eigen::Vector3d(0.17, 0.3, 0.1), 12 + frame % 5),
            sphere(hand_at(t_ns), 0.06, random_rotation(rng), 16, 32));
  m.capture_ns = 1'000'000'000 + t_ns;
  return m;
}

MarginOptions estimated_acceleration() {
  MarginOptions o;
  o.worst_case_acceleration = false;
  return o;
}

TEST(VelocityField, NewMeshTakesTheVelocityOfThePartItBelongsTo) {
  std::mt19937 rng(3);
  MotionTracker tracker;
  std::optional<MeshMotion> motion;
  ActorMesh fitted;
  for (int f = 0; f < 2; ++f) {
    fitted = swing_at(f * kFrameNs, f, rng);
    auto m = tracker.update(fitted);
    ASSERT_TRUE(m);
    if (*m) motion = **m;
  }
  ASSERT_TRUE(motion);
  auto field = VelocityField::create(fitted, *motion, 0.15);
  ASSERT_TRUE(field) << field.error().message;
  const ActorMesh next = swing_at(2 * kFrameNs, 2, rng);
  auto v = field->at(next);
  ASSERT_TRUE(v) << v.error().message;
  ASSERT_EQ(v->size(), next.vertices.size());
  // The hand's true velocity at the middle of the fit's interval (t = 20 ms).
  const Eigen::Vector3d hand_v = (hand_at(kFrameNs) - hand_at(0)) / (kFrameNs * 1e-9);
  const Eigen::Vector3d hand = hand_at(2 * kFrameNs);
  int hand_n = 0, torso_n = 0;
  double hand_err = 0, torso_speed = 0;
  for (std::size_t i = 0; i < next.vertices.size(); ++i) {
    const Eigen::Vector3d p = next.vertices[i].cast<double>();
    const Eigen::Vector3d vi = (*v)[i].cast<double>();
    if ((p - hand).norm() < 0.07) {
      hand_err = std::max(hand_err, (vi - hand_v).norm());
      ++hand_n;
    } else if ((p - hand).norm() > 0.3) {
      torso_speed = std::max(torso_speed, vi.norm());
      ++torso_n;
    }
  }
  std::printf(
      "hand: %d vertices, largest velocity error %.3f m/s of %.2f; torso: %d vertices, "
      "fastest %.3f m/s\n",
      hand_n, hand_err, hand_v.norm(), torso_n, torso_speed);
  ASSERT_GT(hand_n, 100);
  ASSERT_GT(torso_n, 100);
  EXPECT_LT(hand_err, 0.35);  // 1.5 m/s: the fit's own error, no torso mixed in
  EXPECT_LT(torso_speed, 0.15);

  // Bad input: a motion of another mesh, a mesh older than the fitted one, a bad cell size.
  ActorMesh other = next;
  other.vertices.pop_back();
  EXPECT_FALSE(VelocityField::create(other, *motion, 0.15));
  EXPECT_FALSE(VelocityField::create(fitted, *motion, 0.0));
  ActorMesh older = next;
  older.capture_ns = fitted.capture_ns - 1;
  EXPECT_FALSE(field->at(older));
  EXPECT_FALSE(predict_by_velocities(next, std::span(v->data(), v->size() - 1), 0.01));
  EXPECT_FALSE(predict_by_velocities(next, *v, -0.01));
}

// Meshes 0..2 fitted (the fit of mesh 2 has accelerations), mesh 3 latched with mesh 2's field
// and shown `latency` after its capture: its latched prediction, grown by the margin with the
// velocity's age (40 ms + 20 ms), covers the true swing then.
TEST(VelocityField, LatchedPredictionCoversTheSwingWithTheAgedMargin) {
  for (const double latency : {0.03, 0.06}) {
    std::mt19937 rng(9);
    MotionTracker tracker;
    std::optional<MeshMotion> motion;
    ActorMesh fitted;
    for (int f = 0; f < 3; ++f) {
      fitted = swing_at(f * kFrameNs, f, rng);
      auto m = tracker.update(fitted);
      ASSERT_TRUE(m);
      if (*m) motion = **m;
    }
    ASSERT_TRUE(motion && motion->max_acceleration_mps2);
    auto field = VelocityField::create(fitted, *motion, 0.15);
    ASSERT_TRUE(field);
    const ActorMesh latched = swing_at(3 * kFrameNs, 3, rng);
    const double age = kFrameNs * 1e-9 + 0.5 * motion->dt_s;
    const auto v = field->at(latched);
    ASSERT_TRUE(v);
    const auto fresh = security_margin(estimated_acceleration(), latency, 0, &*motion);
    const auto aged = security_margin(estimated_acceleration(), latency, 0, &*motion, age);
    ASSERT_TRUE(fresh && aged && aged->predicted);
    // a L (L + 2 age) / 2 instead of a L (L + dt) / 2.
    EXPECT_NEAR(aged->motion_m - fresh->motion_m,
                aged->acceleration_mps2 * latency * (2 * age - motion->dt_s) / 2, 1e-9);
    const ActorMesh truth = swing_at(3 * kFrameNs + int64_t(latency * 1e9), 99, rng);
    auto predicted = predict_by_velocities(latched, *v, latency);
    ASSERT_TRUE(predicted);
    const auto covered = coverage(*grow_mesh(*predicted, aged->margin_m), truth);
    const auto unpredicted = coverage(*grow_mesh(latched, aged->margin_m), truth);
    double lo = 0, hi = 0.1;  // the margin the latched prediction needs (whole millimetres)
    while (hi - lo > 0.0011) {
      const double mid = std::round(500 * (lo + hi)) / 1000;
      (coverage(*grow_mesh(*predicted, mid), truth).outside == 0 ? hi : lo) = mid;
    }
    std::printf(
        "latency %.0f ms: margin %.1f mm (fresh fit's formula %.1f mm; worst case a: %.1f mm), "
        "needed %.0f mm; outside: latched prediction %d/%d, unpredicted %d\n",
        latency * 1e3, aged->margin_m * 1e3, fresh->margin_m * 1e3,
        security_margin({}, latency, 0, &*motion, age)->margin_m * 1e3, hi * 1e3, covered.outside,
        covered.points, unpredicted.outside);
    EXPECT_EQ(covered.outside, 0);
    EXPECT_GT(unpredicted.outside, 20);  // the margin alone does not cover the moving hand
    EXPECT_LE(hi, aged->margin_m + 1e-9);
  }
}

}  // namespace
}  // namespace studio::projector
