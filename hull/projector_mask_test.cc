// The projector's actor mask from the viewpoint cut (hull/projector_mask.h) against the other
// mask source, the actor mesh drawn from the projector (the hull's mesh with exact crossings,
// rasterised at the projector's pixel centres), in the simulated studio: the true masks of the
// default rig (5 ring cameras + overhead) and a 1920x1080 projector lighting the back wall. Both
// must agree with IoU >= 0.98 (issue 15, "mask sources"); each is also scored against the
// simulator's own truth of the actor in the projector's image (sim/projector_light.h).

#include "hull/projector_mask.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "sim/cameras.h"
#include "sim/projector_light.h"
#include "sim/studio.h"
#include "support/masks.h"
#include "testing/raster.h"

namespace studio::hull {
namespace {

TEST(ProjectorMask, ExpandSamplesGivesEachPixelItsNearestSample) {
  RunMask s(3, 2);
  s.push_run(0, 1, 2);
  s.push_run(1, 0, 1);
  s.push_run(1, 2, 3);
  s.finish();
  const RunMask full = expand_samples(s, 4, 10, 7);
  // Sample (1, 0) is pixel (4, 0): pixels x in [2, 6), y in [0, 2).
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 10; ++x) {
      const int sx = (x + 2) / 4, sy = (y + 2) / 4;
      const bool expect = sy < 2 && sx < 3 && s.contains(sx, sy);
      EXPECT_EQ(full.contains(x, y), expect) << x << "," << y;
    }
  EXPECT_TRUE(full.valid());
  EXPECT_EQ(expand_samples(s, 1, 3, 2), s);
}

TEST(ProjectorMask, AgreesWithTheMeshDrawnFromTheProjector) {
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::arm_swing;
  so.actor.seed = 3;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
  ASSERT_TRUE(studio) << studio.error().message;
  const Projector proj = sim::studio_projector(sim::Cyclorama{}, {0.5, 2.5, 3.8});
  GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = Axis::y;
  g.cells_u = g.cells_v = 256;
  CutOptions cut;
  cut.threads = 2;
  const std::size_t n = std::size_t(studio->camera_count());
  for (const int frame : {5, 30}) {
    std::vector<Mask> truth(n);
    std::vector<RunMask> runs(n);
    std::vector<View> views;
    for (std::size_t c = 0; c < n; ++c) {
      studio->render(int(c), frame, nullptr, &truth[c]);
      runs[c] = RunMask::from_mask(truth[c].view());
      views.push_back({&studio->cameras()[c], &runs[c]});
    }
    auto hull = visual_hull(g, views, cut);
    ASSERT_TRUE(hull) << hull.error().message;
    Mesh mesh = segment_marching_cubes(*hull);
    ASSERT_TRUE(refine_crossings(mesh, *hull, views, cut));
    const RunMask from_mesh = RunMask::from_mask(testing::rasterise(mesh, proj.camera).view());

    ProjectorMaskOptions po;
    po.step = 1;
    po.cut = cut;
    auto cut_mask =
        projector_mask(proj.camera, Eigen::AlignedBox3d(g.box_min, g.box_max), views, po);
    ASSERT_TRUE(cut_mask) << cut_mask.error().message;
    ASSERT_EQ(cut_mask->width(), 1920);
    const RunMask actor =
        RunMask::from_mask(sim::actor_in_projector(proj.camera, studio->truth(frame).body).view());
    ASSERT_GT(actor.area(), 20000u);
    const double agree = support::iou(*cut_mask, from_mesh);
    std::printf(
        "frame %d: viewpoint cut vs mesh IoU %.4f; vs the true actor: cut %.4f, mesh %.4f\n", frame,
        agree, support::iou(*cut_mask, actor), support::iou(from_mesh, actor));
    EXPECT_GE(agree, 0.98) << "frame " << frame;
    // Step 2 (the node's default) keeps the agreement.
    po.step = 2;
    auto coarse = projector_mask(proj.camera, Eigen::AlignedBox3d(g.box_min, g.box_max), views, po);
    ASSERT_TRUE(coarse);
    EXPECT_GE(support::iou(*coarse, *cut_mask), 0.98);
  }
  ProjectorMaskOptions bad;
  bad.step = 0;
  EXPECT_FALSE(projector_mask(proj.camera, Eigen::AlignedBox3d(g.box_min, g.box_max), {}, bad));
}

}  // namespace
}  // namespace studio::hull
