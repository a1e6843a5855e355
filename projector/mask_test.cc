// Actor mask: margin formula, motion estimation between re-tessellated meshes, prediction and the
// grown mask. A mesh "covers" another when every vertex and face centre of the other lies inside it
// (winding number, computed here independently of the library).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "projector/actor_mesh.h"
#include "projector/mask_geometry.h"
#include "projector/mask_margin.h"
#include "projector/motion.h"
#include "testing/shapes.h"
#include "testing/swing_meshes.h"

namespace studio::projector {
namespace {

constexpr int64_t kFrameNs = 40'000'000;  // 25 fps

// The test shapes and the independent coverage check (projector/testing/shapes.h).
using testing::box;
using testing::Coverage;
using testing::coverage;
using testing::merge;
using testing::random_rotation;
using testing::sphere;
using testing::winding;

// ---- margin formula ---------------------------------------------------------------------------

TEST(MaskMargin, ComponentsFollowTheFormula) {
  MarginOptions o;                    // floor 10 mm, cap 200 mm, sigma_v 0.05 m/s
  o.worst_case_acceleration = false;  // the estimate's formula (the default is checked below)
  // No motion known: floor + head speed x latency.
  auto m = security_margin(o, 0.08, 1.0, nullptr);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->margin_m, 0.01 + 1.0 * 0.08, 1e-12);
  EXPECT_FALSE(m->predicted);
  EXPECT_FALSE(m->capped);
  // Mesh motion faster than the head, no acceleration estimate yet: the fastest region counts.
  MeshMotion motion;
  motion.dt_s = 0.04;
  motion.max_speed_mps = 1.5;
  m = security_margin(o, 0.08, 1.0, &motion);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->margin_m, 0.01 + 1.5 * 0.08, 1e-12);
  EXPECT_FALSE(m->predicted);
  // With an acceleration estimate: floor + a L (L + dt) / 2 + sigma_v L.
  motion.max_acceleration_mps2 = 3.75;
  m = security_margin(o, 0.06, 1.0, &motion);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->predicted);
  EXPECT_NEAR(m->motion_m, 0.5 * 3.75 * 0.06 * (0.06 + 0.04) + 0.05 * 0.06, 1e-12);
  EXPECT_NEAR(m->margin_m, 0.01 + m->motion_m, 1e-12);
  EXPECT_NEAR(m->margin_m, 0.02425, 1e-9);
  // Prediction switched off: back to v L.
  MarginOptions off = o;
  off.prediction = false;
  EXPECT_NEAR(security_margin(off, 0.06, 1.0, &motion)->margin_m, 0.01 + 1.5 * 0.06, 1e-12);
  // The head tracker disagrees with the mesh motion (head much faster): no prediction.
  m = security_margin(o, 0.06, 2.5, &motion);
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->predicted);
  EXPECT_NEAR(m->margin_m, 0.01 + 2.5 * 0.06, 1e-12);
  // Cap.
  m = security_margin(o, 0.1, 5.0, nullptr);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->capped);
  EXPECT_EQ(m->margin_m, 0.2);
  EXPECT_NEAR(m->motion_m, 0.5, 1e-12);
  // Still actor: the floor.
  EXPECT_EQ(security_margin(o, 0.05, 0.0, nullptr)->margin_m, 0.01);
  // Bad input.
  EXPECT_FALSE(security_margin(o, -0.01, 1.0, nullptr));
  EXPECT_FALSE(security_margin(o, NAN, 1.0, nullptr));
  EXPECT_FALSE(security_margin(o, 0.05, -1.0, nullptr));
  MarginOptions bad = o;
  bad.cap_m = 0.001;
  EXPECT_FALSE(security_margin(bad, 0.05, 1.0, nullptr));
}

TEST(MaskMargin, DefaultAssumesTheWorstCaseAccelerationWhateverTheEstimate) {
  // An actor at rest (estimate 0) may start moving during the latency: the default margin takes
  // a = max_acceleration_mps2 (15 m/s^2). At the 40 ms: 36 mm; at 150 ms: capped.
  const MarginOptions o;
  MeshMotion still;
  still.dt_s = 0.04;
  still.max_speed_mps = 0;
  still.max_acceleration_mps2 = 0;
  still.robust_acceleration_mps2 = 0;
  auto m = security_margin(o, 0.04, 0.0, &still);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->predicted);
  EXPECT_EQ(m->acceleration_mps2, 15.0);
  EXPECT_NEAR(m->margin_m, 0.01 + 0.5 * 15 * 0.04 * 0.08 + 0.05 * 0.04, 1e-12);
  EXPECT_TRUE(security_margin(o, 0.15, 0.0, &still)->capped);
  // Without prediction (no motion known: the first mesh, after a gap) the same worst case: an
  // actor still at the capture may be moving at the display: v L + a L^2 / 2, not v L alone.
  m = security_margin(o, 0.06, 0.0, nullptr);
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->predicted);
  EXPECT_NEAR(m->margin_m, 0.01 + 0.5 * 15 * 0.06 * 0.06, 1e-12);
  m = security_margin(o, 0.06, 1.0, nullptr);
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->margin_m, 0.01 + 1.0 * 0.06 + 0.5 * 15 * 0.06 * 0.06, 1e-12);
  // Control: with the estimate, the still actor gets the floor and the velocity term only, and
  // the no-prediction term is v L alone.
  MarginOptions estimate = o;
  estimate.worst_case_acceleration = false;
  EXPECT_NEAR(security_margin(estimate, 0.04, 0.0, &still)->margin_m, 0.01 + 0.05 * 0.04, 1e-12);
  EXPECT_NEAR(security_margin(estimate, 0.06, 1.0, nullptr)->margin_m, 0.01 + 0.06, 1e-12);
}

TEST(MaskMargin, LatencyWindowTakesAHighQuantile) {
  LatencyWindow w(100, 0.95);
  EXPECT_EQ(w.latency_s(), 0);
  for (int i = 1; i <= 100; ++i) ASSERT_TRUE(w.add(1'000'000'000, 1'000'000'000 + i * 1'000'000));
  EXPECT_NEAR(w.latency_s(), 0.095, 1e-12);
  // Older samples leave the window.
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(w.add(0, 20'000'000));
  EXPECT_NEAR(w.latency_s(), 0.020, 1e-12);
  EXPECT_EQ(w.size(), 100u);
  // Rejected: shown before captured, or absurdly late.
  EXPECT_FALSE(w.add(100, 50));
  EXPECT_FALSE(w.add(0, 11'000'000'000));
  EXPECT_EQ(w.size(), 100u);
}

// ---- motion and prediction --------------------------------------------------------------------

struct Outcome {
  double needed_m = 0;  // smallest margin (1 mm steps) at which the prediction covers the truth
  double margin_m = 0;
  double no_prediction_margin_m = 0;
  Coverage predicted;      // the predicted mesh grown by the margin vs the truth at display time
  Coverage unpredicted;    // the last mesh grown by the same margin (must fail: the test can fail)
  Coverage no_prediction;  // the last mesh grown by the no-prediction margin
  MeshMotion motion;
};

MarginOptions estimated_acceleration() {  // the motion fit's own acceleration, not the worst case
  MarginOptions o;
  o.worst_case_acceleration = false;
  return o;
}

// Feeds three consecutive meshes of `at(frame)` (re-tessellated each frame), then predicts the
// last one to display time and compares with the truth there. The margin uses the motion fit's
// acceleration by default (what the "<= 30 mm with prediction" measures).
template <class MeshAt>
Outcome run(MeshAt at, double latency_s,
            const MarginOptions& margin_options = estimated_acceleration()) {
  MotionTracker tracker;
  std::optional<MeshMotion> motion;
  ActorMesh last;
  for (int frame = 0; frame < 3; ++frame) {
    last = at(frame * kFrameNs, frame);
    auto m = tracker.update(last);
    EXPECT_TRUE(m) << m.error().message;
    if (m) motion = *m;
  }
  Outcome out;
  EXPECT_TRUE(motion.has_value());
  EXPECT_TRUE(motion->max_acceleration_mps2.has_value());
  out.motion = *motion;
  const auto margin = security_margin(margin_options, latency_s, 0.0, &*motion);
  EXPECT_TRUE(margin && margin->predicted);
  out.margin_m = margin->margin_m;
  MarginOptions off = margin_options;
  off.prediction = false;
  out.no_prediction_margin_m = security_margin(off, latency_s, 0.0, &*motion)->margin_m;
  const int64_t shown = 2 * kFrameNs + static_cast<int64_t>(latency_s * 1e9);  // after frame 2
  const ActorMesh truth = at(shown, 99);
  auto predicted = predict(last, *motion, latency_s);
  EXPECT_TRUE(predicted);
  out.predicted = coverage(*grow_mesh(*predicted, out.margin_m), truth);
  double lo = 0, hi = 0.1;  // bisection on whole millimetres
  while (hi - lo > 0.0011) {
    const double mid = std::round(500 * (lo + hi)) / 1000;
    (coverage(*grow_mesh(*predicted, mid), truth).outside == 0 ? hi : lo) = mid;
  }
  out.needed_m = hi;
  out.unpredicted = coverage(*grow_mesh(last, out.margin_m), truth);
  out.no_prediction = coverage(*grow_mesh(last, out.no_prediction_margin_m), truth);
  return out;
}

TEST(MaskPrediction, SphereAt1_5MetresPerSecondIsCoveredWithASmallMargin) {
  std::mt19937 rng(5);
  const Eigen::Vector3d velocity = Eigen::Vector3d(1.2, 0.3, -0.84).normalized() * 1.5;
  auto at = [&](int64_t t_ns, int) {
    ActorMesh m =
        sphere(Eigen::Vector3d(0, 1.6, 0) + velocity * (1e-9 * t_ns), 0.12, random_rotation(rng));
    m.capture_ns = 1'000'000'000 + t_ns;
    return m;
  };
  const Outcome o = run(at, 0.06);
  std::printf(
      "sphere: speed %.3f m/s, acceleration %.2f m/s^2, margin %.1f mm (no prediction %.1f mm), "
      "outside: predicted %d/%d, unpredicted %d, no-prediction %d; needed with prediction %.0f "
      "mm\n",
      o.motion.max_speed_mps, *o.motion.max_acceleration_mps2, 1e3 * o.margin_m,
      1e3 * o.no_prediction_margin_m, o.predicted.outside, o.predicted.points,
      o.unpredicted.outside, o.no_prediction.outside, 1e3 * o.needed_m);
  EXPECT_NEAR(o.motion.max_speed_mps, 1.5, 0.1);
  EXPECT_LE(o.margin_m, 0.030);
  EXPECT_EQ(o.predicted.outside, 0);
  EXPECT_GT(o.unpredicted.outside, 100);  // the small margin alone does not cover a moving actor
  EXPECT_GE(o.no_prediction_margin_m, 0.09);
  EXPECT_EQ(o.no_prediction.outside, 0);
}

TEST(MaskPrediction, BoxAt1_5MetresPerSecondIsCoveredWithASmallMargin) {
  const Eigen::Vector3d velocity = Eigen::Vector3d(-0.5, 0.2, 1.0).normalized() * 1.5;
  auto at = [&](int64_t t_ns, int frame) {
    // 10, 11, 12 ... cells per edge: never the same vertices twice.
    ActorMesh m = box(Eigen::Vector3d(0.2, 1.2, 0.1) + velocity * (1e-9 * t_ns),
                      Eigen::Vector3d(0.2, 0.3, 0.12), 10 + frame % 7);
    m.capture_ns = 1'000'000'000 + t_ns;
    return m;
  };
  const Outcome o = run(at, 0.06);
  std::printf(
      "box: speed %.3f m/s, acceleration %.2f m/s^2, margin %.1f mm (no prediction %.1f mm), "
      "outside: predicted %d/%d, unpredicted %d, no-prediction %d; needed with prediction %.0f "
      "mm\n",
      o.motion.max_speed_mps, *o.motion.max_acceleration_mps2, 1e3 * o.margin_m,
      1e3 * o.no_prediction_margin_m, o.predicted.outside, o.predicted.points,
      o.unpredicted.outside, o.no_prediction.outside, 1e3 * o.needed_m);
  EXPECT_LE(o.margin_m, 0.030);
  EXPECT_EQ(o.predicted.outside, 0);
  EXPECT_GT(o.unpredicted.outside, 100);
  EXPECT_EQ(o.no_prediction.outside, 0);
}

TEST(MaskPrediction, SwingingHandNextToAStillTorsoIsCoveredWithASmallMargin) {
  // A hand (sphere, 6 cm) on a 0.6 m arc at 1.5 m/s (centripetal 3.75 m/s^2) beside a still torso.
  std::mt19937 rng(9);
  const Eigen::Vector3d shoulder(0.25, 1.45, 0);
  const double radius = 0.6, omega = 1.5 / radius;
  auto at = [&](int64_t t_ns, int frame) {
    const double angle = -1.2 + omega * 1e-9 * t_ns;
    const Eigen::Vector3d hand =
        shoulder +
        radius * Eigen::Vector3d(0.3 * std::cos(angle), -std::cos(angle) * 0.95, std::sin(angle))
                     .normalized();
    ActorMesh m =
        merge(box(Eigen::Vector3d(-0.05, 1.2, 0), Eigen::Vector3d(0.17, 0.3, 0.1), 12 + frame % 5),
              sphere(hand, 0.06, random_rotation(rng), 16, 32));
    m.capture_ns = 1'000'000'000 + t_ns;
    return m;
  };
  const Outcome o = run(at, 0.06);
  std::printf(
      "swing: speed %.3f m/s, acceleration %.2f m/s^2, margin %.1f mm (no prediction %.1f mm), "
      "outside: predicted %d/%d, unpredicted %d, no-prediction %d; needed with prediction %.0f "
      "mm\n",
      o.motion.max_speed_mps, *o.motion.max_acceleration_mps2, 1e3 * o.margin_m,
      1e3 * o.no_prediction_margin_m, o.predicted.outside, o.predicted.points,
      o.unpredicted.outside, o.no_prediction.outside, 1e3 * o.needed_m);
  EXPECT_NEAR(o.motion.max_speed_mps, 1.5, 0.25);
  EXPECT_LE(o.margin_m, 0.030);
  EXPECT_EQ(o.predicted.outside, 0);
  EXPECT_GT(o.unpredicted.outside, 20);
  EXPECT_EQ(o.no_prediction.outside, 0);
}

TEST(MaskPrediction, StillActorHasNoMotion) {
  std::mt19937 rng(2);
  ActorMesh a = sphere({0, 1.5, 0}, 0.15, random_rotation(rng));
  ActorMesh b = sphere({0, 1.5, 0}, 0.15, random_rotation(rng));
  a.capture_ns = 0;
  b.capture_ns = kFrameNs;
  auto m = estimate_motion(a, b);
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_LT(m->max_speed_mps, 0.05);
}

// ---- mask geometry and bad input ----------------------------------------------------------------

TEST(MaskGeometry, GrownMeshClearsTheOriginalByTheMargin) {
  // Box corners are the hard case for a normal offset: every face must move out by >= margin.
  const ActorMesh b = box({0, 1, 0}, {0.2, 0.3, 0.1}, 6);
  auto grown = grow_mesh(b, 0.02);
  ASSERT_TRUE(grown);
  // Points 19 mm outside each face centre and near the corners are inside the grown mesh.
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.219, 1, 0), Eigen::Vector3d(0, 1.319, 0), Eigen::Vector3d(0, 1, -0.119),
        Eigen::Vector3d(0.215, 1.315, 0.115), Eigen::Vector3d(-0.215, 0.685, -0.115)})
    EXPECT_GT(winding(*grown, p), 0.5) << p.transpose();
  // ... and points far outside are not.
  EXPECT_LT(winding(*grown, {0.26, 1, 0}), 0.5);
}

TEST(MaskGeometry, DenseMeshIsSimplifiedAndStillClearsTheOriginalByTheMargin) {
  // A hull-like dense mesh (~20k triangles): grown from at most max_triangles, the simplifier's
  // error added to the push, so every point 19 mm outside the original is still covered.
  std::mt19937 rng(11);
  const ActorMesh dense = sphere({0, 1.2, 0}, 0.3, Eigen::Matrix3d::Identity(), 72, 144);
  ASSERT_GT(dense.triangles.size(), 20000u);
  auto grown = grow_mesh(dense, 0.02);
  ASSERT_TRUE(grown);
  EXPECT_LE(grown->triangles.size(), GrowOptions{}.max_triangles);
  std::normal_distribution<double> n(0, 1);
  int uncovered = 0, far_covered = 0;
  for (int k = 0; k < 300; ++k) {
    const Eigen::Vector3d d = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    if (winding(*grown, Eigen::Vector3d(0, 1.2, 0) + (0.3 + 0.019) * d) < 0.5) ++uncovered;
    if (winding(*grown, Eigen::Vector3d(0, 1.2, 0) + (0.3 + 0.02 + 0.06) * d) > 0.5) ++far_covered;
  }
  EXPECT_EQ(uncovered, 0);
  // The extra push stays small: the error (<= 1.5 x 1 % of the extent) and min_cosine's
  // allowance at the simplified mesh's sharper vertices.
  EXPECT_EQ(far_covered, 0);
  // Without simplification the same mesh is kept whole.
  GrowOptions whole;
  whole.max_triangles = 0;
  auto full = grow_mesh(dense, 0.02, whole);
  ASSERT_TRUE(full);
  EXPECT_EQ(full->triangles.size(), dense.triangles.size());
}

TEST(MaskGeometry, TwoStageSimplificationCoversTheSwingingActorLikeTheEdgeCollapse) {
  // The simulated actor swinging its arm (~21k triangles: clustered, then edge-collapsed, by
  // default) grown by 1 cm: every sampled vertex and face centre of the mesh lies inside the
  // mask, both ways; the two-stage error is the larger (it adds the clustering's), and the
  // mask is fatter by about that, not by a multiple (points 5 cm beyond the surface).
  const auto& meshes = testing::swing_meshes();
  GrowOptions collapse_only;
  collapse_only.presimplify = false;
  ASSERT_TRUE(GrowOptions{}.presimplify);
  for (std::size_t f = 0; f < meshes.size(); f += 3) {
    const ActorMesh& m = meshes[f];
    ASSERT_GT(m.triangles.size(), 4 * GrowOptions{}.max_triangles);
    auto two = simplify_for_mask(m);
    auto one = simplify_for_mask(m, collapse_only);
    ASSERT_TRUE(two && one);
    EXPECT_LE(two->mesh.triangles.size(), GrowOptions{}.max_triangles);
    EXPECT_GT(two->error_m, one->error_m);
    EXPECT_LT(two->error_m, 0.05);
    int far[2] = {0, 0};  // two-stage, collapse alone
    for (int k = 0; k < 2; ++k) {
      const MaskBase& base = k == 0 ? *two : *one;
      auto grown = grow_mask(base, 0.01);
      ASSERT_TRUE(grown);
      const std::vector<Eigen::Vector3f> normals = vertex_normals(m);
      int outside = 0;
      for (std::size_t i = 0; i < m.vertices.size(); i += 37) {
        if (winding(*grown, m.vertices[i].cast<double>()) < 0.5) ++outside;
        const Eigen::Vector3d beyond = (m.vertices[i] + 0.05f * normals[i]).cast<double>();
        if (winding(*grown, beyond) > 0.5) ++far[k];
      }
      for (std::size_t t = 0; t < m.triangles.size(); t += 53) {
        const auto& tri = m.triangles[t];
        const Eigen::Vector3d c =
            (m.vertices[tri[0]] + m.vertices[tri[1]] + m.vertices[tri[2]]).cast<double>() / 3;
        if (winding(*grown, c) < 0.5) ++outside;
      }
      EXPECT_EQ(outside, 0) << "frame " << f << (k == 0 ? " two-stage" : " collapse");
    }
    // Points 5 cm out along the normal fall inside a mask where the body folds (arm at the
    // torso) and where min_cosine's allowance pushes sharp vertices further: the two-stage
    // mask, pushed by its larger error, covers more of them, but not twice as many (measured:
    // 148 / 84, 112 / 70, 152 / 83 of ~700 points).
    std::printf("frame %zu: points 5 cm out inside the mask: two-stage %d, collapse %d\n", f,
                far[0], far[1]);
    EXPECT_LE(far[0], 2 * far[1] + 10) << "frame " << f;
  }
}

TEST(MaskGeometry, RefusesMalformedMeshes) {
  ActorMesh good = box({0, 1, 0}, {0.2, 0.3, 0.1}, 2);
  ASSERT_TRUE(good.validate());
  ASSERT_TRUE(grow_mesh(good, 0.01));
  ActorMesh empty;
  EXPECT_NE(empty.validate().error().message.find("empty"), std::string::npos);
  ActorMesh out_of_range = good;
  out_of_range.triangles[3][1] = 100000;
  EXPECT_NE(out_of_range.validate().error().message.find("names vertex 100000"), std::string::npos);
  ActorMesh nan = good;
  nan.vertices[2].x() = NAN;
  EXPECT_FALSE(nan.validate());
  EXPECT_FALSE(grow_mesh(nan, 0.01));
  EXPECT_FALSE(grow_mesh(good, -0.01));
  // The tracker rejects a bad mesh and restarts; an old mesh is refused without losing state.
  MotionTracker tracker;
  good.capture_ns = 0;
  ASSERT_TRUE(tracker.update(good));
  EXPECT_FALSE(tracker.update(out_of_range));
  ActorMesh later = good;
  later.capture_ns = kFrameNs;
  auto first_after_reset = tracker.update(later);
  ASSERT_TRUE(first_after_reset);
  EXPECT_FALSE(first_after_reset->has_value());  // restarted: no motion yet
  EXPECT_FALSE(tracker.update(good));            // older than the last one
  ActorMesh next = good;
  next.capture_ns = 2 * kFrameNs;
  auto m = tracker.update(next);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->has_value());
  // Motion from meshes too far apart or out of order.
  EXPECT_FALSE(estimate_motion(next, good));
  ActorMesh much_later = good;
  much_later.capture_ns = 2'000'000'000;
  EXPECT_FALSE(estimate_motion(good, much_later));
  EXPECT_FALSE(predict(next, **m, -1));
  EXPECT_FALSE(predict(box({0, 1, 0}, {0.2, 0.3, 0.1}, 3), **m, 0.05));
}

}  // namespace
}  // namespace studio::projector
