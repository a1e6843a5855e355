// Exact crossings (hull/crossing_refine.h) on a synthetic actor seen by 6 ring cameras: only the
// vertices between an inside and an outside column move, along their grid edge and strictly
// between the two columns; topology is kept; the volume shrinks (the half-cell placement is
// biased outwards) towards the true volume; the result does not depend on the thread count.
#include "hull/crossing_refine.h"

#include <gtest/gtest.h>

#include "support/cameras.h"
#include "testing/synthetic.h"

namespace studio::hull {
namespace {

struct Fixture {
  testing::Scene scene = testing::actor();
  std::vector<Camera> cameras = support::camera_ring(6, 352, 288, 4.0, 1.6, {0, 0.9, 0}, 300);
  std::vector<RunMask> masks;
  std::vector<View> views;
  GridSpec grid;
  Fixture() {
    for (const Camera& c : cameras) masks.push_back(testing::render_mask(c, scene));
    for (std::size_t c = 0; c < cameras.size(); ++c) views.push_back({&cameras[c], &masks[c]});
    grid.box_min = {-1, 0, -1};
    grid.box_max = {1, 2, 1};
    grid.cells_u = grid.cells_v = 96;
  }
};

TEST(CrossingRefine, MovesEdgeVerticesInwardsKeepsTopologyAndIgnoresThreads) {
  const Fixture f;
  const SegmentSet set = visual_hull(f.grid, f.views).value();
  const Mesh plain = segment_marching_cubes(set);
  Mesh one = plain, two = plain;
  CutOptions o1, o2;
  o2.threads = 2;
  ASSERT_TRUE(refine_crossings(one, set, f.views, o1).has_value());
  ASSERT_TRUE(refine_crossings(two, set, f.views, o2).has_value());
  // Enough vertices that 2 threads really split them (at least 4096 per thread).
  ASSERT_GT(plain.vertices.size(), 2 * 4096u);
  ASSERT_EQ(one.vertices.size(), plain.vertices.size());
  ASSERT_EQ(one.triangles, plain.triangles);
  EXPECT_EQ(one.vertices, two.vertices);  // bit-identical with 2 threads

  const double cell = f.grid.du();
  std::size_t moved = 0;
  for (std::size_t k = 0; k < plain.vertices.size(); ++k) {
    const Eigen::Vector3f d = one.vertices[k] - plain.vertices[k];
    if (d.norm() == 0) continue;
    ++moved;
    EXPECT_EQ(d.y(), 0.f);                                    // never along the column axis
    EXPECT_TRUE(d.x() == 0.f || d.z() == 0.f);                // along one grid edge
    EXPECT_LT(d.norm(), 0.5 * cell * (1 - 0.02 * 2) + 1e-5);  // strictly between the columns
  }
  EXPECT_GT(moved, plain.vertices.size() / 10);
  const MeshTopology topo = check_topology(one);
  EXPECT_TRUE(topo.watertight());
  EXPECT_TRUE(topo.oriented());
  const double truth = f.scene.volume_estimate(f.grid.box_min, f.grid.box_max, 200);
  std::printf("volume: true %.5f, half-cell %.5f, exact crossings %.5f m^3\n", truth,
              plain.volume(), one.volume());
  EXPECT_LT(one.volume(), plain.volume());
  EXPECT_LT(std::abs(one.volume() - truth), std::abs(plain.volume() - truth));
}

TEST(CrossingRefine, RejectsMaskOfWrongSize) {
  const Fixture f;
  const SegmentSet set = visual_hull(f.grid, f.views).value();
  Mesh mesh = segment_marching_cubes(set);
  const Mesh before = mesh;
  const RunMask small(100, 80);
  std::vector<View> views = f.views;
  views[2].mask = &small;
  EXPECT_FALSE(refine_crossings(mesh, set, views).has_value());
  EXPECT_EQ(mesh.vertices, before.vertices);
}

}  // namespace
}  // namespace studio::hull
