// The demo probe's truth (truth.h): the true mask it scores the live meshes against is the
// simulator's geometric silhouette, cast directly from the true body (sim::actor_in_projector,
// pixel-centre rays) instead of rendering every camera's image to get it. Both must be the same
// pixels as the mask SimulatedStudio::render() produces beside its image, on every camera of the
// example rig and frames of every motion the demo runs.
#include "truth.h"

#include <gtest/gtest.h>

#include "capture/sim_source.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/projector_light.h"
#include "sim/studio.h"

namespace studio::demo {
namespace {

TEST(DemoTruth, CastSilhouetteEqualsTheRenderedTrueMask) {
  const std::vector<Camera> cameras = sim::ring_cameras();
  const sim::StudioOptions scene = capture::SimSourceOptions{}.studio;
  auto studio = sim::SimulatedStudio::create(cameras, scene);
  ASSERT_TRUE(studio.has_value());
  Mask rendered;
  std::size_t pixels = 0;
  for (const int64_t frame : {0, 17, 40, 73, 120, 260}) {
    const sim::FrameTruth truth = studio->truth(frame);
    for (int c = 0; c < studio->camera_count(); ++c) {
      studio->render(c, frame, nullptr, &rendered);
      const Mask cast = sim::actor_in_projector(cameras[std::size_t(c)], truth.body);
      std::size_t differ = 0;
      for (int y = 0; y < rendered.height(); ++y)
        for (int x = 0; x < rendered.width(); ++x) {
          differ += (rendered(x, y) != 0) != (cast(x, y) != 0);
          pixels += rendered(x, y) != 0;
        }
      EXPECT_EQ(differ, 0u) << "frame " << frame << " " << cameras[std::size_t(c)].id;
    }
  }
  EXPECT_GT(pixels, 6u * 6 * 1000);  // the actor is in view (a positive control)
}

// The scorer on its own: the live hull's mesh of the true masks (160 columns, exact crossings,
// the demo's configuration) scores above the demo's 0.95 bound, an empty mesh 0.
TEST(DemoTruth, ScoresTheHullOfTheTrueMasksAndAnEmptyMesh) {
  const std::vector<Camera> cameras = sim::ring_cameras();
  auto scorer = TruthScorer::create(cameras);
  auto studio = sim::SimulatedStudio::create(cameras, capture::SimSourceOptions{}.studio);
  ASSERT_TRUE(scorer.has_value() && studio.has_value());
  const int64_t frame = 40;
  std::vector<Mask> truth;
  studio->render_all(frame, nullptr, &truth);
  std::vector<RunMask> runs;
  for (const Mask& m : truth) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<hull::View> views;
  for (std::size_t c = 0; c < cameras.size(); ++c) views.push_back({&cameras[c], &runs[c]});
  hull::GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.cells_u = g.cells_v = 160;
  auto set = hull::visual_hull(g, views);
  ASSERT_TRUE(set.has_value());
  hull::Mesh mesh = hull::segment_marching_cubes(*set, {.normals = false});
  ASSERT_TRUE(hull::refine_crossings(mesh, *set, views).has_value());
  const MeshScore good = scorer->score_meshes(uint64_t(frame), {mesh});
  EXPECT_GE(good.mean_iou, 0.95);
  EXPECT_LE(good.mean_iou, 1.0);
  const MeshScore none = scorer->score_meshes(uint64_t(frame), {});
  EXPECT_EQ(none.mean_iou, 0.0);
}

}  // namespace
}  // namespace studio::demo

namespace studio::demo {
namespace {

// The true head between frames (the projector frames' display instants fall between them).
TEST(DemoTruth, TrueHeadBetweenFramesIsOnTheSegment) {
  auto scorer = TruthScorer::create(sim::ring_cameras());
  ASSERT_TRUE(scorer.has_value());
  const Eigen::Vector3d a = scorer->true_head(40), b = scorer->true_head(41);
  EXPECT_LT((scorer->true_head_at(40.0) - a).norm(), 1e-12);
  EXPECT_LT((scorer->true_head_at(40.25) - (a + 0.25 * (b - a))).norm(), 1e-12);
  EXPECT_LT((scorer->true_head_at(41.0) - b).norm(), 1e-12);
}

}  // namespace
}  // namespace studio::demo
