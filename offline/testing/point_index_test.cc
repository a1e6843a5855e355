// testing/point_index.h against a brute-force scan: the same double for every query (near the
// points, inside their box, far outside it), with a grid forced coarse, and the documented
// limits (empty index, nothing within max_shells).
#include "testing/point_index.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace studio::offline::testing {
namespace {

double brute(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& x) {
  double best2 = std::numeric_limits<double>::infinity();
  for (const auto& p : pts) best2 = std::min(best2, (p - x).squaredNorm());
  return std::sqrt(best2);
}

// Points on a sphere's surface (as the metric's samples lie on a surface) and a few scattered.
std::vector<Eigen::Vector3d> cloud(std::mt19937_64& rng, int n) {
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  std::vector<Eigen::Vector3d> pts;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d d(g(rng), g(rng), g(rng));
    pts.push_back(k % 10 == 0 ? Eigen::Vector3d(u(rng), 1 + u(rng), u(rng))
                              : Eigen::Vector3d(0, 1, 0) + 0.4 * d.normalized());
  }
  return pts;
}

TEST(PointIndex, EqualsABruteForceScan) {
  std::mt19937_64 rng(3);
  const auto pts = cloud(rng, 4000);
  std::uniform_real_distribution<double> near(-0.7, 0.7), far(-3, 3);
  const PointIndex fine(pts, 0.01), coarse(pts, 0.01, 64, 64);  // the second: at most 64 cells
  EXPECT_GT(coarse.cell(), 0.1);
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector3d x = k % 3 == 2 ? Eigen::Vector3d(far(rng), 1 + far(rng), far(rng))
                                         : Eigen::Vector3d(near(rng), 1 + near(rng), near(rng));
    const double want = brute(pts, x);
    EXPECT_EQ(coarse.nearest(x), want) << k;
    // Far queries need more than 64 shells of 1 cm: only those within reach are compared.
    if (want < 0.6) EXPECT_EQ(fine.nearest(x), want) << k;
  }
  for (const auto& p : pts) EXPECT_EQ(fine.nearest(p), 0.0);
}

TEST(PointIndex, EmptyAndOutOfReachAreInfinite) {
  EXPECT_EQ(PointIndex({}, 0.01).nearest(Eigen::Vector3d::Zero()),
            std::numeric_limits<double>::infinity());
  const PointIndex one({Eigen::Vector3d(0, 0, 0)}, 0.01, 8);
  EXPECT_EQ(one.nearest(Eigen::Vector3d(0.05, 0, 0)), 0.05);
  EXPECT_EQ(one.nearest(Eigen::Vector3d(1, 0, 0)), std::numeric_limits<double>::infinity());
}

}  // namespace
}  // namespace studio::offline::testing
