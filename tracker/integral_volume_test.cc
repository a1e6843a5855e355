#include "tracker/integral_volume.h"

#include <gtest/gtest.h>

#include <random>

namespace studio::tracker {
namespace {

int64_t brute_count(const OccupancyGrid& g, Eigen::Vector3i lo, Eigen::Vector3i hi) {
  lo = lo.cwiseMax(0);
  hi = hi.cwiseMin(g.dims());
  int64_t s = 0;
  for (int x = lo.x(); x < hi.x(); ++x)
    for (int y = lo.y(); y < hi.y(); ++y)
      for (int z = lo.z(); z < hi.z(); ++z) s += g.at(x, y, z);
  return s;
}

TEST(IntegralVolume, BoxCountsMatchBruteForceIncludingClippedAndEmptyBoxes) {
  std::mt19937 rng(7);
  OccupancyGrid g({0, 0, 0}, {0.1, 0.05, 0.1}, {13, 17, 11});
  std::uniform_int_distribution<int> value(0, 255), coin(0, 2);
  for (int x = 0; x < 13; ++x)
    for (int y = 0; y < 17; ++y)
      for (int z = 0; z < 11; ++z) g.at(x, y, z) = coin(rng) == 0 ? 0 : uint8_t(value(rng));
  const IntegralVolume iv(g);
  EXPECT_EQ(iv.total(), brute_count(g, {0, 0, 0}, g.dims()));
  std::uniform_int_distribution<int> c(-5, 22);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3i lo(c(rng), c(rng), c(rng)), hi(c(rng), c(rng), c(rng));
    ASSERT_EQ(iv.count(lo, hi), brute_count(g, lo, hi))
        << lo.transpose() << " / " << hi.transpose();
  }
}

TEST(IntegralVolume, EmptyGridCountsZero) {
  const IntegralVolume iv(OccupancyGrid({0, 0, 0}, {1, 1, 1}, {0, 0, 0}));
  EXPECT_EQ(iv.total(), 0);
  EXPECT_EQ(iv.count({-3, -3, -3}, {3, 3, 3}), 0);
}

TEST(OccupancyGrid, CropKeepsEveryOccupiedVoxelOnTheSameLattice) {
  OccupancyGrid g({-1, 0, -1}, {0.1, 0.1, 0.1}, {20, 20, 20});
  g.at(3, 4, 5) = 255;
  g.at(7, 15, 6) = 10;
  const OccupancyGrid c = g.cropped_to_occupied();
  EXPECT_EQ(c.dims(), Eigen::Vector3i(5, 12, 2));
  EXPECT_TRUE(c.origin().isApprox(Eigen::Vector3d(-0.7, 0.4, -0.5)));
  EXPECT_EQ(c.at(0, 0, 0), 255);
  EXPECT_EQ(c.at(4, 11, 1), 10);
  EXPECT_DOUBLE_EQ(c.occupied_volume(), g.occupied_volume());
  EXPECT_TRUE(OccupancyGrid({0, 0, 0}, {1, 1, 1}, {4, 4, 4}).cropped_to_occupied().empty());
}

TEST(OccupancyGrid, MakeGridUsesCubicVoxelsFromTheColumnCount) {
  const OccupancyGrid g = make_grid({-1.5, 0, -1.5}, {1.5, 2.4, 1.5}, 128);
  EXPECT_EQ(g.dims(), Eigen::Vector3i(128, 103, 128));
  EXPECT_NEAR(g.voxel().x(), 3.0 / 128, 1e-12);
  EXPECT_EQ(g.voxel().x(), g.voxel().y());
}

}  // namespace
}  // namespace studio::tracker
