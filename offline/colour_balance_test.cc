// The colour balance (offline/colour_balance.h) against the simulated studio's truth: cameras
// whose responses differ (sim::StudioOptions::camera_response) are equalised from the frame's own
// hull, the carve then keeps the true surface it removes without the balance, and a rig whose
// cameras agree is left as it is.
#include "offline/colour_balance.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/photo_carve.h"
#include "sim/cameras.h"
#include "testing/truth.h"

namespace studio::offline {
namespace {

struct Scene {
  testing::Frame f;
  std::vector<ColourView> views;
  std::vector<hull::View> cut;
  hull::SegmentSet set;
  hull::Mesh hull_mesh;
  std::vector<std::array<double, 3>> response;
};

// 8 ring cameras + overhead (704x576), the actor at `frame`, keyed masks, the hull at `grid`.
Scene make_scene(sim::Motion motion, int64_t frame, std::vector<std::array<double, 3>> response,
                 int grid) {
  sim::RingOptions ring;
  ring.count = 9;
  sim::StudioOptions so;
  so.actor.motion = motion;
  so.camera_response = response;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(ring), so).value();
  Scene s;
  s.response = std::move(response);
  s.f = testing::render_frame(studio, frame);
  s.views = s.f.views();
  for (const auto& v : s.views) s.cut.push_back({v.camera, v.mask});
  s.set = hull::visual_hull(testing::studio_grid(grid), s.cut).value();
  s.hull_mesh = hull::segment_marching_cubes(s.set);
  EXPECT_TRUE(hull::refine_crossings(s.hull_mesh, s.set, s.cut));
  return s;
}

// The largest relative difference of `gains` from the simulated ones (sim::balancing_gains).
double worst_gain_error(const std::vector<std::array<double, 3>>& response,
                        const std::vector<Eigen::Vector3f>& gains) {
  const auto want = sim::balancing_gains(response);
  double worst = 0;
  for (std::size_t c = 0; c < want.size(); ++c)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(gains[c][k] / want[c][std::size_t(k)] - 1));
  return worst;
}

TEST(ColourBalance, RecoversTheSimulatedCamerasResponses) {
  // Exposure within +-10 %, white balance within +-5 % on red and blue: up to 15 grey levels
  // apart on a bright shirt, against the carve's 6.
  const auto response = sim::random_camera_response(9, 3, 0.10, 0.05);
  const Scene s = make_scene(sim::Motion::idle, 10, response, 128);
  ColourBalanceOptions o;
  const ColourBalance cb = estimate_colour_balance(s.hull_mesh, s.views, o).value();
  const double before =
      worst_gain_error(response, std::vector<Eigen::Vector3f>(9, Eigen::Vector3f::Ones()));
  const double after = worst_gain_error(response, cb.gains);
  std::printf(
      "  %zu points seen twice, %d pairs, residual %.4f; worst gain error %.2f %% (no "
      "balance: %.2f %%)\n",
      cb.points, cb.pairs, cb.residual, 100 * after, 100 * before);
  // Measured: 1.72 % (5.88 % without the balance); the rest is view-dependent light the gains
  // cannot model (the spill towards grazing views, each camera's own LED ring).
  EXPECT_GT(before, 0.05);
  EXPECT_LT(after, 0.025);
  EXPECT_GE(cb.pairs, 16);  // the ring's neighbours and the overhead with the ring
  EXPECT_TRUE(cb.applied);  // beyond the tolerance: applied
  EXPECT_EQ(cb.gains, cb.estimated);
  o.threads = 2;
  const ColourBalance two = estimate_colour_balance(s.hull_mesh, s.views, o).value();
  EXPECT_EQ(two.gains, cb.gains);
  EXPECT_EQ(two.points, cb.points);

  // The balanced images: each camera's pixels multiplied by its gains.
  std::vector<Image<Rgb8>> store;
  const std::vector<ColourView> balanced = apply_colour_balance(s.views, cb, &store);
  ASSERT_EQ(balanced.size(), s.views.size());
  for (std::size_t c = 0; c < balanced.size(); ++c) {
    const Rgb8 in = s.views[c].image.row(300)[350], out = balanced[c].image.row(300)[350];
    EXPECT_NEAR(out.r, std::min(255.0, in.r * double(cb.gains[c].x())), 0.51);
    EXPECT_NEAR(out.b, std::min(255.0, in.b * double(cb.gains[c].z())), 0.51);
  }
}

// A take's estimate pools its frames' shared points (ColourBalanceEstimator): the counts add up,
// and three walk frames give the gains as well as one frame does.
TEST(ColourBalance, PooledOverTheFramesOfATake) {
  const auto response = sim::random_camera_response(9, 3, 0.10, 0.05);
  ColourBalanceEstimator take(9);
  std::size_t points = 0;
  double worst_single = 0;
  for (const int64_t frame : {5, 35, 65}) {
    const Scene s = make_scene(sim::Motion::walk, frame, response, 128);
    ASSERT_TRUE(take.add(s.hull_mesh, s.views));
    const ColourBalance one = estimate_colour_balance(s.hull_mesh, s.views).value();
    points += one.points;
    worst_single = std::max(worst_single, worst_gain_error(response, one.estimated));
  }
  const ColourBalance pooled = take.solve();
  const double worst = worst_gain_error(response, pooled.estimated);
  std::printf("  3 walk frames: pooled worst gain error %.2f %%, single frames up to %.2f %%\n",
              100 * worst, 100 * worst_single);
  EXPECT_EQ(pooled.frames, 3);
  EXPECT_EQ(pooled.points, points);
  EXPECT_TRUE(pooled.applied);  // beyond the tolerance: applied
  EXPECT_EQ(pooled.gains, pooled.estimated);
  EXPECT_LT(worst, 0.03);
  // A frame of another rig is refused and adds nothing.
  const Scene s = make_scene(sim::Motion::walk, 5, {}, 64);
  EXPECT_FALSE(take.add(s.hull_mesh, std::span(s.views).first(8)));
  EXPECT_EQ(take.solve().points, points);
  EXPECT_EQ(ColourBalanceEstimator(9).solve().gains,
            std::vector<Eigen::Vector3f>(9, Eigen::Vector3f::Ones()));
}

// The positive control's other half: cameras that agree get gains of 1 (within the estimate's
// noise), so the default changes nothing on a consistent rig.
TEST(ColourBalance, LeavesAConsistentRigAlone) {
  const Scene s = make_scene(sim::Motion::crouch, 45, {}, 128);
  ColourBalanceOptions o;
  const ColourBalance cb = estimate_colour_balance(s.hull_mesh, s.views, o).value();
  float worst = 0;
  for (const auto& g : cb.estimated) worst = std::max(worst, (g.array() - 1).abs().maxCoeff());
  std::printf("  %zu points, %d pairs, residual %.4f, largest |gain - 1| %.4f\n", cb.points,
              cb.pairs, cb.residual, worst);
  EXPECT_LT(worst, 0.015);  // measured 0.98 %
  // Within the tolerance (2 %): the images are left as they are.
  EXPECT_FALSE(cb.applied);
  for (const auto& g : cb.gains) EXPECT_EQ(g, Eigen::Vector3f::Ones());
  ColourBalanceOptions strict;
  strict.tolerance = 0;
  EXPECT_EQ(estimate_colour_balance(s.hull_mesh, s.views, strict).value().gains, cb.estimated);
}

// What the balance is for: the carve on a rig whose cameras differ (exposure +-10 %, white
// balance +-5 %) removes the true surface without it (the carved mesh farther from the truth than
// the hull), and with it carves as on a rig whose cameras agree.
TEST(ColourBalance, TheCarveOnDifferingCamerasNeedsIt) {
  const auto carved_distance = [](const Scene& s, bool balance) {
    std::vector<Image<Rgb8>> store;
    std::vector<ColourView> views = s.views;
    if (balance)
      views = apply_colour_balance(  // as studio-hull offline: its own hull at 128 columns
          s.views, estimate_colour_balance(testing::studio_grid(256), s.views).value(), &store);
    CarveOptions co;
    co.threads = 2;
    const CarveResult carved = photo_carve(s.set, views, co).value();
    const hull::Mesh mesh = refined_mesh(carved.set, s.set, views, 2).value();
    return testing::surface_distance(mesh, s.f.truth.body).both;
  };
  const Scene agree = make_scene(sim::Motion::idle, 10, {}, 256);
  const Scene differ =
      make_scene(sim::Motion::idle, 10, sim::random_camera_response(9, 3, 0.10, 0.05), 256);
  const double hull = testing::surface_distance(differ.hull_mesh, differ.f.truth.body).both.mean;
  const testing::Distances reference = carved_distance(agree, false);
  const testing::Distances without = carved_distance(differ, false);
  const testing::Distances with = carved_distance(differ, true);
  std::printf(
      "  surface distance mean / p95 (mm): hull %.2f; carved, cameras agreeing %.2f / "
      "%.2f; differing %.2f / %.2f, balanced %.2f / %.2f\n",
      1e3 * hull, 1e3 * reference.mean, 1e3 * reference.p95, 1e3 * without.mean, 1e3 * without.p95,
      1e3 * with.mean, 1e3 * with.p95);
  EXPECT_GT(without.mean, hull);  // measured 5.92 against 5.73 mm
  EXPECT_LT(with.mean, 0.92 * hull);
  EXPECT_LT(with.mean, 1.02 * reference.mean);
  EXPECT_LT(with.p95, 1.03 * reference.p95);
}

// A live estimate (the preview's, preview/rig_balance.h): a frame may hold only some cameras'
// images (the others take no part), and a window of the newest samples per pair follows a
// camera whose response changes.
TEST(ColourBalance, FramesOfSomeCamerasAndABoundedWindow) {
  const auto response = sim::random_camera_response(9, 3, 0.10, 0.05);
  const Scene differ = make_scene(sim::Motion::idle, 10, response, 128);
  const Scene agree = make_scene(sim::Motion::idle, 10, {}, 128);
  // Cameras 0, 1 and 7 only (cam0 and its ring neighbours, as a preview between them textures
  // with): pairs 0-1 and 0-7 (1 and 7, 90 degrees apart, share too little), every other gain 1.
  std::vector<ColourView> some(9);
  for (int c : {0, 1, 7}) some[std::size_t(c)] = differ.views[std::size_t(c)];
  ColourBalanceEstimator three(9);
  ASSERT_TRUE(three.add(differ.hull_mesh, some));
  const ColourBalance b = three.solve();
  EXPECT_EQ(b.pairs, 2);
  const auto truth = sim::balancing_gains(response);
  double worst = 0;
  for (int i : {0, 1, 7})
    for (int j : {0, 1, 7})
      for (int k = 0; k < 3 && i < j; ++k)
        worst = std::max(worst, std::abs(double(b.estimated[std::size_t(i)][k] /
                                                b.estimated[std::size_t(j)][k]) /
                                             (truth[std::size_t(i)][std::size_t(k)] /
                                              truth[std::size_t(j)][std::size_t(k)]) -
                                         1));
  std::printf("  cameras 0, 1, 7 alone: worst pair ratio error %.2f %%\n", 100 * worst);
  EXPECT_LT(worst, 0.025);  // measured 1.39 %
  for (int c : {2, 3, 4, 5, 6, 8}) EXPECT_EQ(b.estimated[std::size_t(c)], Eigen::Vector3f::Ones());
  // The linked set: 0, 1 and 7 together (named by camera 0), the rest linked to none.
  EXPECT_EQ(b.linked_set, (std::vector<int>{0, 0, -1, -1, -1, -1, -1, 0, -1}));
  // One view present: nothing to compare, the frame counts.
  std::vector<ColourView> one(9);
  one[0] = differ.views[0];
  ASSERT_TRUE(three.add(differ.hull_mesh, one));
  EXPECT_EQ(three.solve().frames, 2);
  // A view half given (a mask without its camera) is refused.
  std::vector<ColourView> half = some;
  half[4].mask = differ.views[4].mask;
  EXPECT_FALSE(three.add(differ.hull_mesh, half));

  // The window: the cameras agree, then their responses change. Keeping only the newest frame's
  // samples, the estimate is the new frame's alone; pooling everything, it is a mix of both.
  ColourBalanceOptions window;
  window.max_pair_samples = 1;  // a frame is kept whole: the newest frame
  ColourBalanceEstimator follows(9, window), pools(9);
  for (ColourBalanceEstimator* e : {&follows, &pools}) {
    ASSERT_TRUE(e->add(agree.hull_mesh, agree.views));
    ASSERT_TRUE(e->add(differ.hull_mesh, differ.views));
  }
  const ColourBalance alone = estimate_colour_balance(differ.hull_mesh, differ.views).value();
  EXPECT_EQ(follows.solve().estimated, alone.estimated);
  EXPECT_NE(pools.solve().estimated, alone.estimated);
  EXPECT_GT(worst_gain_error(response, pools.solve().estimated),
            worst_gain_error(response, alone.estimated));
}

TEST(ColourBalance, RefusesBadInputAndKeepsUnlinkedCamerasAtOne) {
  const Scene s = make_scene(sim::Motion::idle, 10, {}, 64);
  ColourBalanceOptions bad;
  bad.min_level = 300;
  auto r = estimate_colour_balance(s.hull_mesh, s.views, bad);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
  EXPECT_FALSE(estimate_colour_balance(s.hull_mesh, {}));
  std::vector<ColourView> wrong = s.views;
  wrong[2].image =
      ImageView<const Rgb8>(wrong[2].image.data(), 100, 100, wrong[2].image.stride_bytes());
  auto w = estimate_colour_balance(s.hull_mesh, wrong);
  ASSERT_FALSE(w);
  EXPECT_NE(w.error().message.find("image is 100x100"), std::string::npos) << w.error().message;
  EXPECT_FALSE(estimate_colour_balance(testing::studio_grid(64), s.views, {}, 0));
  // An empty mesh: no points, no pairs, every gain 1; so is a camera no pair reaches.
  const ColourBalance none = estimate_colour_balance(hull::Mesh{}, s.views).value();
  EXPECT_EQ(none.points, 0u);
  EXPECT_EQ(none.pairs, 0);
  EXPECT_FALSE(none.applied);  // (every estimate 1: nothing to apply, nothing reported applied)
  for (const auto& g : none.gains) EXPECT_EQ(g, Eigen::Vector3f::Ones());
  EXPECT_EQ(none.linked_set, std::vector<int>(s.views.size(), -1));
  ColourBalanceOptions strict;
  strict.min_samples = 1 << 30;
  const ColourBalance unlinked = estimate_colour_balance(s.hull_mesh, s.views, strict).value();
  EXPECT_GT(unlinked.points, 0u);
  for (const auto& g : unlinked.gains) EXPECT_EQ(g, Eigen::Vector3f::Ones());
  std::vector<Image<Rgb8>> store;
  const auto same = apply_colour_balance(s.views, unlinked, &store);
  EXPECT_TRUE(store.empty());
  EXPECT_EQ(same[0].image.data(), s.views[0].image.data());
}

}  // namespace
}  // namespace studio::offline
