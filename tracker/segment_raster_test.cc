#include "tracker/segment_raster.h"

#include <gtest/gtest.h>

namespace studio::tracker {
namespace {

hull::GridSpec spec(hull::Axis axis) {
  hull::GridSpec g;
  g.box_min = {0, 0, 0};
  g.box_max = {2, 2, 2};
  g.axis = axis;
  g.cells_u = g.cells_v = 20;  // 0.1 m columns
  return g;
}

TEST(SegmentRaster, KeepsTheVolumeAndTheContinuousEnds) {
  for (hull::Axis axis : {hull::Axis::y, hull::Axis::x, hull::Axis::z}) {
    const hull::GridSpec g = spec(axis);
    std::vector<std::vector<hull::Interval>> cols(g.columns());
    cols[g.cells_u * 7 + 3] = {{0.23f, 0.71f}, {1.05f, 1.08f}};
    cols[g.cells_u * 8 + 4] = {{0.5f, 0.6f}};
    const auto set = hull::SegmentSet::from_columns(g, cols);
    const OccupancyGrid grid = rasterise(set);
    EXPECT_NEAR(grid.occupied_volume(), set.volume(), 0.002 * 0.01) << hull::axis_name(axis);
    // Cropped to the occupied cells: 2 x 2 columns, t from 0.2 to 1.1.
    const int a = g.a(), u = g.u(), v = g.v();
    EXPECT_EQ(grid.dims()[u], 2);
    EXPECT_EQ(grid.dims()[v], 2);
    EXPECT_EQ(grid.dims()[a], 9);
    EXPECT_NEAR(grid.origin()[a], 0.2, 1e-9);
    EXPECT_NEAR(grid.origin()[u], g.box_min[u] + 0.3, 1e-9);
    // Column (3, 7): voxel t in [0.2, 0.3) holds 0.7 of it, [0.3, 0.7) full, [0.7, 0.8) 0.1.
    Eigen::Vector3i at = Eigen::Vector3i::Zero();
    at[u] = 0, at[v] = 0, at[a] = 0;
    EXPECT_NEAR(grid.at(at.x(), at.y(), at.z()), 0.7 * 255, 1.0);
    at[a] = 3;
    EXPECT_EQ(grid.at(at.x(), at.y(), at.z()), 255);
    at[a] = 5;
    EXPECT_NEAR(grid.at(at.x(), at.y(), at.z()), 0.1 * 255, 1.0);
    at[a] = 8;
    EXPECT_NEAR(grid.at(at.x(), at.y(), at.z()), 0.3 * 255, 1.0);
  }
}

TEST(SegmentRaster, EmptyHullGivesAnEmptyGrid) {
  const OccupancyGrid grid = rasterise(hull::SegmentSet::empty(spec(hull::Axis::y)));
  EXPECT_TRUE(grid.empty());
}

TEST(SegmentRaster, FullColumnsFillTheBox) {
  const OccupancyGrid grid = rasterise(hull::SegmentSet::full(spec(hull::Axis::y)));
  EXPECT_EQ(grid.dims(), Eigen::Vector3i(20, 20, 20));
  EXPECT_NEAR(grid.occupied_volume(), 8.0, 1e-9);
}

}  // namespace
}  // namespace studio::tracker
