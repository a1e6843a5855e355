// Real data for the offline refinement (issue 21): the Middlebury dinoSparseRing
// (../shared/data/middlebury_dino, see its README; tests/support/middlebury_dino.h): 15
// calibrated views at 640x480 on a sparse ring of other elevations than the studio's, a matte
// white object under real shading and noise, silhouettes by Middlebury's recipe. What the
// simulated studio cannot vouch for: the carve's incremental judging (photo_carve.h) gives the
// same voxels as judging every surface voxel every iteration on images it was not made on; the
// colour balance (colour_balance.h) recovers camera gains applied to real images.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/colour_balance.h"
#include "offline/photo_carve.h"
#include "support/middlebury_dino.h"
#include "testing/same_carve.h"

namespace fs = std::filesystem;

namespace studio::offline {
namespace {

// The dino's views as the carve takes them, and its hull at 96 columns (the tight box + 5 mm).
struct Dino {
  studio::testing::DinoViews data;
  std::vector<ColourView> views;
  std::vector<hull::View> cut;
  hull::SegmentSet set;
};
// nullopt without the shared data (the caller skips) or when it does not load (a failure).
std::optional<Dino> load_dino() {
  const fs::path dir = fs::path(STUDIO_SHARED_DATA) / "middlebury_dino";
  if (!fs::exists(dir / "dinoSR_par.txt")) return std::nullopt;
  auto loaded = studio::testing::load_middlebury_dino(dir.string());
  EXPECT_TRUE(loaded) << loaded.error().message;
  if (!loaded) return std::nullopt;
  Dino d;
  d.data = std::move(*loaded);
  for (std::size_t k = 0; k < d.data.cameras.size(); ++k) {
    const cv::Mat& m = d.data.rgb[k];
    d.views.push_back({&d.data.cameras[k],
                       ImageView<const Rgb8>(reinterpret_cast<const Rgb8*>(m.data), m.cols, m.rows,
                                             std::ptrdiff_t(m.step)),
                       &d.data.masks[k]});
    d.cut.push_back({&d.data.cameras[k], &d.data.masks[k]});
  }
  hull::GridSpec g;
  g.box_min = studio::testing::DinoViews::box_min(0.005);
  g.box_max = studio::testing::DinoViews::box_max(0.005);
  g.cells_u = g.cells_v = 96;
  d.set = hull::visual_hull(g, d.cut).value();
  return d;
}

TEST(PhotoCarveDino, IncrementalJudgingCarvesTheSameVoxelsOnRealImages) {
  const auto dino = load_dino();
  if (!dino) {
    if (!HasFailure()) GTEST_SKIP() << "no middlebury_dino in the shared test data";
    return;
  }
  const std::vector<ColourView>& views = dino->views;
  const hull::SegmentSet& set = dino->set;
  // The dino's shading differs between views more than the studio's cloth: two thresholds, the
  // default and a tighter one that carves more.
  for (const double threshold : {6.0, 4.0}) {
    CarveOptions every, incremental;
    every.threshold = incremental.threshold = threshold;
    every.threads = incremental.threads = 2;
    every.incremental = false;
    const CarveResult a = photo_carve(set, views, every).value();
    const CarveResult b = photo_carve(set, views, incremental).value();
    std::printf(
        "dino, threshold %.0f: %zu of %zu voxels carved in %d iterations; judged %zu "
        "(every voxel) vs %zu (incremental)\n",
        threshold, a.carved, a.voxels, a.iterations, a.judged, b.judged);
    testing::expect_same_carve(a, b);
  }
}

// Known gains applied to the dino's real images (another object, camera geometry, shading and
// noise than the studio's) are recovered: the estimate on the altered images, times the applied
// gains, equals the estimate on the originals (both up to the rig's mean, which the balance
// cannot know). The dino's own estimate is printed: its light moved with the gantry, so its views
// differ in brightness by themselves.
TEST(ColourBalanceDino, RecoversGainsAppliedToRealImages) {
  const auto dino = load_dino();
  if (!dino) {
    if (!HasFailure()) GTEST_SKIP() << "no middlebury_dino in the shared test data";
    return;
  }
  const std::vector<ColourView>& views = dino->views;
  const std::size_t n = views.size();
  // Display-space gains in [0.8, 1] per camera and channel (below 1: nothing clips).
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.8, 1.0);
  std::vector<Eigen::Vector3d> applied(n);
  std::vector<Image<Rgb8>> altered;
  altered.reserve(n);
  std::vector<ColourView> views_altered = views;
  for (std::size_t k = 0; k < n; ++k) {
    const ImageView<const Rgb8>& img = views[k].image;
    applied[k] = {u(rng), u(rng), u(rng)};
    Image<Rgb8>& a = altered.emplace_back(img.width(), img.height());
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x) {
        const Rgb8 p = img.row(y)[x];
        const auto q = [](double v) { return uint8_t(std::lround(v)); };
        a(x, y) = {q(p.r * applied[k].x()), q(p.g * applied[k].y()), q(p.b * applied[k].z())};
      }
    views_altered[k].image = a.view();
  }
  hull::Mesh mesh = hull::segment_marching_cubes(dino->set);
  ASSERT_TRUE(hull::refine_crossings(mesh, dino->set, dino->cut));
  const ColourBalance own = estimate_colour_balance(mesh, views).value();
  const ColourBalance est = estimate_colour_balance(mesh, views_altered).value();
  // est * applied, brought to a geometric mean of 1 per channel, against own.
  double worst = 0, worst_own = 0;
  for (int c = 0; c < 3; ++c) {
    double mean_log = 0;
    for (std::size_t k = 0; k < n; ++k) mean_log += std::log(est.estimated[k][c] * applied[k][c]);
    mean_log /= double(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double combined = std::exp(std::log(est.estimated[k][c] * applied[k][c]) - mean_log);
      worst = std::max(worst, std::abs(combined / own.estimated[k][c] - 1));
      worst_own = std::max(worst_own, double(std::abs(own.estimated[k][c] - 1)));
    }
  }
  std::printf(
      "dino: %zu points seen twice, %d pairs, residual %.4f; own gains up to %.1f %% off "
      "1; applied gains recovered within %.2f %%\n",
      own.points, own.pairs, own.residual, 100 * worst_own, 100 * worst);
  EXPECT_GE(own.pairs, int(n) - 1);
  EXPECT_LT(worst, 0.01);
}

}  // namespace
}  // namespace studio::offline
