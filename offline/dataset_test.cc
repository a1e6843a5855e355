// Real data for the offline refinement (issue 21): the Middlebury dinoSparseRing
// (../shared/data/middlebury_dino, see its README; tests/support/middlebury_dino.h): 15
// calibrated views at 640x480 on a sparse ring of other elevations than the studio's, a matte
// white object under real shading and noise, silhouettes by Middlebury's recipe. What the
// simulated studio cannot vouch for: the carve's incremental judging (photo_carve.h) gives the
// same voxels as judging every surface voxel every iteration on images it was not made on.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "hull/silhouette_cut.h"
#include "offline/photo_carve.h"
#include "support/middlebury_dino.h"
#include "testing/same_carve.h"

namespace fs = std::filesystem;

namespace studio::offline {
namespace {

TEST(PhotoCarveDino, IncrementalJudgingCarvesTheSameVoxelsOnRealImages) {
  const fs::path dir = fs::path(STUDIO_SHARED_DATA) / "middlebury_dino";
  if (!fs::exists(dir / "dinoSR_par.txt")) GTEST_SKIP() << "no " << dir << " (shared test data)";
  auto dino = studio::testing::load_middlebury_dino(dir.string());
  ASSERT_TRUE(dino) << dino.error().message;
  std::vector<ColourView> views;
  std::vector<hull::View> cut;
  for (std::size_t k = 0; k < dino->cameras.size(); ++k) {
    const cv::Mat& m = dino->rgb[k];
    views.push_back({&dino->cameras[k],
                     ImageView<const Rgb8>(reinterpret_cast<const Rgb8*>(m.data), m.cols, m.rows,
                                           std::ptrdiff_t(m.step)),
                     &dino->masks[k]});
    cut.push_back({&dino->cameras[k], &dino->masks[k]});
  }
  hull::GridSpec g;
  g.box_min = studio::testing::DinoViews::box_min(0.005);
  g.box_max = studio::testing::DinoViews::box_max(0.005);
  g.cells_u = g.cells_v = 96;
  const hull::SegmentSet set = hull::visual_hull(g, cut).value();
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

}  // namespace
}  // namespace studio::offline
