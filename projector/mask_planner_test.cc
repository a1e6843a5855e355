// MaskPlanner (projector/mask_planner.h): a still actor gets the floor margin; a moving one is
// moved forward by its predicted motion to the display time (its predicted mask covers where it
// really is then); a refused mesh keeps the previous one; the latency window fills from shown().
#include "projector/mask_planner.h"

#include <gtest/gtest.h>

namespace studio::projector {
namespace {

// A finely tessellated sphere (enough vertices per motion region) of radius r at c.
ActorMesh sphere(const Eigen::Vector3f& c, float r, int64_t capture_ns) {
  ActorMesh m;
  const int n = 24;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const float th = float(M_PI) * i / n, ph = float(M_PI) * j / n;
      m.vertices.push_back(c + r * Eigen::Vector3f(std::sin(th) * std::cos(ph), std::cos(th),
                                                   std::sin(th) * std::sin(ph)));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const uint32_t a = i * 2 * n + j, b = i * 2 * n + (j + 1) % (2 * n), c2 = a + 2 * n,
                     d = b + 2 * n;
      m.triangles.push_back({a, c2, b});
      m.triangles.push_back({b, c2, d});
    }
  m.capture_ns = capture_ns;
  return m;
}

Eigen::Vector3f centroid(const ActorMesh& m) {
  Eigen::Vector3f s = Eigen::Vector3f::Zero();
  for (const auto& v : m.vertices) s += v;
  return s / float(m.vertices.size());
}

constexpr int64_t kT0 = 1'700'000'000'000'000'000, kDt = 40'000'000;  // 25 fps

TEST(MaskPlanner, StillActorGetsTheFloorAndMovingActorIsPredicted) {
  MaskPlannerOptions o;
  o.initial_latency_s = 0.04;
  // The fit's own acceleration (the default's worst case is tested in MaskMargin.*): the small
  // margin prediction allows is what this checks.
  o.margin.worst_case_acceleration = false;
  MaskPlanner planner(o);
  ASSERT_TRUE(planner.set_mesh("still", 1, sphere({-1, 1, 0}, 0.2f, kT0)));
  auto plan = planner.plan(kT0 + kDt);
  ASSERT_TRUE(plan);
  EXPECT_NEAR(plan->margin.margin_m, o.margin.floor_m, 1e-9);
  ASSERT_EQ(plan->masks.size(), 1u);

  // A second actor moving at 1 m/s along x, three meshes (the third gives accelerations).
  MaskPlanner moving(o);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(moving.set_mesh("a", k, sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt)));
  const int64_t display = kT0 + 2 * kDt + 50'000'000;  // 50 ms after the last capture
  plan = moving.plan(display);
  ASSERT_TRUE(plan);
  EXPECT_TRUE(plan->margin.predicted);
  EXPECT_EQ(plan->newest_frame, 2u);
  // Grown symmetrically, so the centroid is where the prediction puts the sphere: 0.08 + 0.05.
  EXPECT_NEAR(centroid(plan->masks[0]).x(), 0.13f, 0.01f);
  EXPECT_LT(plan->margin.margin_m, 0.03);

  // Without prediction the margin has to cover the motion instead.
  o.margin.prediction = false;
  MaskPlanner plain(o);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(plain.set_mesh("a", k, sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt)));
  auto p2 = plain.plan(display);
  ASSERT_TRUE(p2);
  EXPECT_FALSE(p2->margin.predicted);
  EXPECT_NEAR(centroid(p2->masks[0]).x(), 0.08f, 0.005f);
  EXPECT_GT(p2->margin.margin_m, plan->margin.margin_m);
}

// Late latching: a latched mesh is drawn before its own fit, moved forward by the previous fit's
// velocities with a margin that counts their age; fit_pending() then gives it its own motion,
// and its plan is set_mesh's.
TEST(MaskPlanner, LatchedMeshUsesThePreviousFitUntilItsOwnIsFitted) {
  MaskPlannerOptions o;
  o.initial_latency_s = 0.04;
  MaskPlanner late(o), eager(o);
  // 1 m/s along x.
  auto at = [](int k) { return sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt); };
  const int64_t display = kT0 + 3 * kDt + 30'000'000;  // 30 ms after the last capture
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(late.latch_mesh("a", k, at(k)));
    ASSERT_TRUE(eager.set_mesh("a", k, at(k)));
    if (k == 0) {  // no fit yet: not predicted
      auto first = late.plan(kT0 + kDt);
      ASSERT_TRUE(first);
      EXPECT_FALSE(first->margin.predicted);
    }
    if (k < 3) {
      EXPECT_EQ(late.fit_pending(), 1);
    }
  }
  auto latched = late.plan(display);
  auto fitted = eager.plan(display);
  ASSERT_TRUE(latched && fitted);
  ASSERT_TRUE(latched->margin.predicted && fitted->margin.predicted);
  EXPECT_EQ(latched->newest_frame, 3u);
  // Moved by the previous fit's 1 m/s: 0.12 + 0.03 (the grown sphere's centroid).
  EXPECT_NEAR(centroid(latched->masks[0]).x(), 0.15f, 0.01f);
  EXPECT_NEAR(latched->margin.velocity_age_s, 0.06, 1e-6);  // 40 ms + half the fit's 40 ms
  EXPECT_NEAR(fitted->margin.velocity_age_s, 0.02, 1e-6);
  const double L = latched->margin.latency_s, a = latched->margin.acceleration_mps2;
  EXPECT_NEAR(latched->margin.motion_m - fitted->margin.motion_m, a * L * (0.12 - 0.04) / 2, 1e-9);
  // Fitted: the same as set_mesh's.
  EXPECT_EQ(late.fit_pending(), 1);
  EXPECT_EQ(late.fit_pending(), 0);
  auto after = late.plan(display);
  ASSERT_TRUE(after);
  EXPECT_NEAR(after->margin.margin_m, fitted->margin.margin_m, 1e-12);
  EXPECT_NEAR(centroid(after->masks[0]).x(), centroid(fitted->masks[0]).x(), 1e-5f);
  // A latched mesh after a gap longer than max_dt_s: not predicted, the known speed instead.
  ASSERT_TRUE(late.latch_mesh("a", 5, sphere({0.2f, 1, 0}, 0.2f, kT0 + 3 * kDt + 600'000'000)));
  auto gap = late.plan(kT0 + 3 * kDt + 640'000'000);
  ASSERT_TRUE(gap);
  EXPECT_FALSE(gap->margin.predicted);
  EXPECT_GT(gap->margin.speed_mps, 0.9);
  // Refused like set_mesh: capture time not after the previous one.
  EXPECT_FALSE(late.latch_mesh("a", 6, sphere({0.2f, 1, 0}, 0.2f, kT0)));
}

// A fit computed off the render thread (FitWorker's fit_motion, installed by apply_fit) gives the
// plan fit_pending gives; a fit that lands after a newer mesh was latched re-latches that mesh
// with its fresher field (the velocity's age drops by a mesh interval), and stale or foreign fits
// are ignored.
TEST(MaskPlanner, FitsInstalledFromElsewhereMatchAndALateFitRelatches) {
  MaskPlannerOptions o;
  MaskPlanner sync(o), async(o);
  MotionTracker tracker(o.motion);  // the fit thread's
  auto at = [](int k) { return sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt); };
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(sync.latch_mesh("a", k, at(k)));
    ASSERT_TRUE(async.latch_mesh("a", k, at(k)));
    EXPECT_EQ(sync.fit_pending(), 1);
    const auto applied = async.apply_fit(fit_motion(tracker, "a", at(k), o.motion.region_size_m));
    EXPECT_EQ(applied, k == 0 ? MaskPlanner::Applied::ignored : MaskPlanner::Applied::own);
  }
  const int64_t display = kT0 + 2 * kDt + 30'000'000;
  auto s = sync.plan(display), a = async.plan(display);
  ASSERT_TRUE(s && a);
  EXPECT_TRUE(a->margin.predicted);
  EXPECT_NEAR(a->margin.margin_m, s->margin.margin_m, 1e-12);
  EXPECT_NEAR(centroid(a->masks[0]).x(), centroid(s->masks[0]).x(), 1e-6f);

  // Mesh 3 latched (field of fit 2: age 40 + 20 ms), then mesh 4 latched before fit 3 lands:
  // from field 2, 80 + 20 ms old.
  ASSERT_TRUE(async.latch_mesh("a", 3, at(3)));
  FitResult fit3 = fit_motion(tracker, "a", at(3), o.motion.region_size_m);
  ASSERT_TRUE(async.latch_mesh("a", 4, at(4)));
  const int64_t display4 = kT0 + 4 * kDt + 30'000'000;
  auto before = async.plan(display4);
  ASSERT_TRUE(before && before->margin.predicted);
  EXPECT_NEAR(before->margin.velocity_age_s, 0.10, 1e-6);
  FitResult again = fit3;
  EXPECT_EQ(async.apply_fit(std::move(fit3)), MaskPlanner::Applied::field);
  auto after = async.plan(display4);
  ASSERT_TRUE(after && after->margin.predicted);
  EXPECT_NEAR(after->margin.velocity_age_s, 0.06, 1e-6);  // from field 3
  EXPECT_LE(after->margin.margin_m, before->margin.margin_m);
  EXPECT_NEAR(centroid(after->masks[0]).x(), 0.16f + 0.03f, 0.01f);  // moved on by 1 m/s
  // The same field again, an unknown actor, a fit newer than the mesh, a refused fit: ignored.
  EXPECT_EQ(async.apply_fit(std::move(again)), MaskPlanner::Applied::ignored);
  MotionTracker other(o.motion);
  FitResult unknown = fit_motion(other, "b", at(4), o.motion.region_size_m);
  EXPECT_EQ(async.apply_fit(std::move(unknown)), MaskPlanner::Applied::ignored);
  FitResult newer;
  newer.actor = "a";
  newer.capture_ns = kT0 + 9 * kDt;
  EXPECT_EQ(async.apply_fit(std::move(newer)), MaskPlanner::Applied::ignored);
  auto unchanged = async.plan(display4);
  ASSERT_TRUE(unchanged);
  EXPECT_NEAR(unchanged->margin.velocity_age_s, 0.06, 1e-6);
  // Mesh 4's own fit: predicted by its own motion from now on.
  EXPECT_EQ(async.apply_fit(fit_motion(tracker, "a", at(4), o.motion.region_size_m)),
            MaskPlanner::Applied::own);
  auto own = async.plan(display4);
  ASSERT_TRUE(own);
  EXPECT_NEAR(own->margin.velocity_age_s, 0.02, 1e-6);
}

// A mesh older at display than the measured latency (no newer mesh came): the margin covers its
// real age, up to the cap.
TEST(MaskPlanner, StaleMeshIsCoveredForItsAge) {
  MaskPlannerOptions o;
  o.margin.prediction = false;
  o.margin.worst_case_acceleration = false;  // v L alone: the age is what this checks
  o.margin.cap_m = 1.0;
  MaskPlanner planner(o);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(planner.set_mesh("a", k, sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt)));
  const int64_t last = kT0 + 2 * kDt;
  auto fresh = planner.plan(last + 20'000'000);  // younger than the initial 40 ms latency
  auto stale = planner.plan(last + 300'000'000);
  ASSERT_TRUE(fresh && stale);
  EXPECT_NEAR(fresh->margin.latency_s, 0.04, 1e-9);
  EXPECT_NEAR(stale->margin.latency_s, 0.30, 1e-9);
  // 1 m/s: 0.3 s of motion is covered.
  EXPECT_NEAR(stale->margin.margin_m, o.margin.floor_m + 0.3, 0.02);
  EXPECT_GT(stale->margin.margin_m, fresh->margin.margin_m + 0.2);

  // Once frames were shown, the lateness measured on them (shown - planned) is added to the age:
  // a frame planned for last + 20 ms and shown 30 ms later than planned.
  ASSERT_TRUE(planner.shown(*fresh, last + 50'000'000));
  EXPECT_NEAR(planner.overrun_s(), 0.030, 1e-9);
  auto next = planner.plan(last + 20'000'000);
  ASSERT_TRUE(next);
  EXPECT_NEAR(next->margin.latency_s, 0.050, 1e-9);
  // Early frames count as on time.
  ASSERT_TRUE(planner.shown(*next, last));
  ASSERT_TRUE(planner.shown(*next, last));
  EXPECT_NEAR(planner.overrun_s(), 0.030, 1e-9);  // the 95 % quantile of {0.03, 0, 0}
}

// After a gap (no motion estimate for the new mesh) the actor is not taken as still: the margin
// covers its last known speed over the latency, and (the default worst case) an acceleration
// during it.
TEST(MaskPlanner, MeshAfterAGapKeepsTheLastKnownSpeed) {
  MaskPlannerOptions o;
  o.margin.cap_m = 1.0;
  MaskPlanner planner(o);
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(planner.set_mesh("a", k, sphere({0.04f * k, 1, 0}, 0.2f, kT0 + k * kDt)));
  const int64_t after_gap = kT0 + 2 * kDt + 2'000'000'000;  // 2 s later: beyond max_dt_s
  ASSERT_TRUE(planner.set_mesh("a", 60, sphere({0.1f, 1, 0}, 0.2f, after_gap)));
  auto plan = planner.plan(after_gap + 100'000'000);
  ASSERT_TRUE(plan);
  EXPECT_FALSE(plan->margin.predicted);
  EXPECT_NEAR(plan->margin.speed_mps, 1.0, 0.1);
  // 1 m/s over 0.1 s, and 15 m/s^2 over it: 0.1 + 0.075.
  EXPECT_NEAR(plan->margin.margin_m, o.margin.floor_m + 0.1 + 0.5 * 15 * 0.01, 0.015);
}

TEST(MaskPlanner, RefusedMeshKeepsThePreviousAndLatencyComesFromShownFrames) {
  MaskPlanner planner;
  ASSERT_TRUE(planner.set_mesh("a", 1, sphere({0, 1, 0}, 0.2f, kT0)));
  EXPECT_FALSE(planner.set_mesh("a", 2, ActorMesh{}));                         // empty
  EXPECT_FALSE(planner.set_mesh("a", 0, sphere({1, 1, 0}, 0.2f, kT0 - kDt)));  // older
  ActorMesh bad = sphere({0, 1, 0}, 0.2f, kT0 + kDt);
  bad.triangles[0][0] = 1u << 30;  // index out of range
  EXPECT_FALSE(planner.set_mesh("a", 2, bad));
  auto plan = planner.plan(kT0 + kDt);
  ASSERT_TRUE(plan);
  ASSERT_EQ(plan->masks.size(), 1u);
  EXPECT_NEAR(centroid(plan->masks[0]).x(), 0.0f, 1e-3f);  // the first mesh
  EXPECT_EQ(plan->newest_capture_ns, kT0);

  EXPECT_DOUBLE_EQ(planner.latency_s(), MaskPlannerOptions{}.initial_latency_s);
  EXPECT_TRUE(planner.shown(*plan, kT0 + 30'000'000));
  EXPECT_NEAR(planner.latency_s(), 0.030, 1e-9);
  EXPECT_FALSE(planner.shown(MaskPlan{}, kT0));  // no mesh: nothing to measure
  planner.remove("a");
  EXPECT_EQ(planner.actors(), 0u);
}

}  // namespace
}  // namespace studio::projector
