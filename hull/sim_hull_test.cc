// Accuracy of the line-segment hull on the simulated studio (issue 5): the TRUE masks of the
// default rig (5 ring cameras + 1 overhead, 704x576, sim/) → RunMask → visual_hull over the
// acting area → segment marching cubes (+ exact crossings, hull/crossing_refine.h) → the mesh
// rasterised back into every camera at pixel centres (testing/raster.h) must match the true mask
// with IoU >= 0.97 in EVERY camera, for frames of the walk, raise-hand and crouch motions.
// Per-camera IoU, missed (-) and extra (+) pixels are printed.
//
// Measured (see BENCHMARKS.md, "Visual hull"): the half-cell placement of plain marching squares
// re-projects about half a cell too wide (extra pixels all along the outline): IoU ~0.93 at 128x128
// columns (2.3 cm cells), ~0.955 at 256x256, 0.96-0.99 at 512x512 where the overhead camera is the
// worst (0.959). With exact crossings every camera is >= 0.979 at 512x512, so the target is met at
// the offline resolution; at 128x128 the crossings raise IoU from ~0.93 to ~0.95.

#include <gtest/gtest.h>

#include <cstdio>

#include "core/run_mask.h"
#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "testing/raster.h"

namespace studio::hull {
namespace {

constexpr double kMinIou = 0.97;

struct Scores {
  std::vector<double> iou;  // per camera and frame
  double worst = 1, mean = 0;
};

Scores run(sim::Motion motion, std::initializer_list<int> frames, int columns, bool refine) {
  Scores out;
  sim::StudioOptions so;
  so.actor.motion = motion;
  so.actor.seed = 3;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
  EXPECT_TRUE(studio.has_value());
  if (!studio) return out;
  GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = Axis::y;
  g.cells_u = g.cells_v = columns;
  CutOptions o;
  o.threads = 2;
  const std::size_t n = std::size_t(studio->camera_count());
  std::vector<Mask> truth(n);
  std::vector<RunMask> runs(n);
  for (const int f : frames) {
    std::vector<View> views;
    for (std::size_t c = 0; c < n; ++c) {
      studio->render(int(c), f, nullptr, &truth[c]);
      runs[c] = RunMask::from_mask(truth[c].view());
      views.push_back({&studio->cameras()[c], &runs[c]});
    }
    auto hull = visual_hull(g, views, o);
    EXPECT_TRUE(hull.has_value());
    if (!hull) return out;
    Mesh mesh = segment_marching_cubes(*hull);
    if (refine) {
      auto ok = refine_crossings(mesh, *hull, views, o);
      EXPECT_TRUE(ok.has_value());
    }
    const MeshTopology topo = check_topology(mesh);
    EXPECT_TRUE(topo.watertight());
    EXPECT_TRUE(topo.oriented());
    std::printf("%-10s %dx%d %s frame %3d IoU:", sim::motion_name(motion), columns, columns,
                refine ? "exact " : "plain ", f);
    for (std::size_t c = 0; c < n; ++c) {
      const Camera& cam = studio->cameras()[c];
      const Mask r = testing::rasterise(mesh, cam);
      std::size_t missed = 0, extra = 0;
      for (int y = 0; y < r.height(); ++y)
        for (int x = 0; x < r.width(); ++x) {
          const bool a = r(x, y) != 0, b = truth[c](x, y) != 0;
          missed += b && !a, extra += a && !b;
        }
      const double q = testing::iou(r, truth[c]);
      std::printf(" %s %.4f (-%zu +%zu)", cam.id.c_str(), q, missed, extra);
      out.iou.push_back(q);
      out.worst = std::min(out.worst, q);
      out.mean += q;
    }
    std::printf("\n");
  }
  out.mean /= double(std::max<std::size_t>(out.iou.size(), 1));
  return out;
}

void expect_every_camera(sim::Motion motion, std::initializer_list<int> frames) {
  const Scores s = run(motion, frames, 512, true);
  ASSERT_EQ(s.iou.size(), frames.size() * 6);
  EXPECT_GE(s.worst, kMinIou) << sim::motion_name(motion) << ": worst camera IoU at 512x512";
}

TEST(SimHull, WalkReprojectsOntoEveryTrueMask) {
  expect_every_camera(sim::Motion::walk, {0, 30, 60, 90});
}
TEST(SimHull, RaiseHandReprojectsOntoEveryTrueMask) {
  expect_every_camera(sim::Motion::raise_hand, {10, 40, 70, 95});
}
TEST(SimHull, CrouchReprojectsOntoEveryTrueMask) {
  expect_every_camera(sim::Motion::crouch, {10, 40, 70, 95});
}

// Exact crossings remove most of the half-cell outward bias at the real-time resolution.
TEST(SimHull, ExactCrossingsImproveCoarseGrids) {
  for (const int columns : {128, 256}) {
    const Scores plain = run(sim::Motion::walk, {0, 60}, columns, false);
    const Scores exact = run(sim::Motion::walk, {0, 60}, columns, true);
    std::printf("%dx%d: mean IoU plain %.4f exact %.4f; worst plain %.4f exact %.4f\n", columns,
                columns, plain.mean, exact.mean, plain.worst, exact.worst);
    EXPECT_GT(exact.mean, plain.mean + 0.005) << columns;
    EXPECT_GT(exact.worst, plain.worst) << columns;
  }
}

}  // namespace
}  // namespace studio::hull
