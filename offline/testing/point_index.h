#pragma once
// Exact nearest-point distances for the surface metric of testing/truth.h (300 000 samples a
// side, so the metric, not the reconstruction, was most of the offline quality tests' time).
//
// Contract: nearest(x) is the Euclidean distance from x to the nearest of the points, exactly
// (the same double as the minimum over a brute-force scan), found within `max_shells` cell shells
// of x's cell; a query with no point that near gets +inf, an empty index always.
//
// Method: a dense uniform grid of cell h over the points' bounding box (counting sort: the points
// stored contiguously by cell, one offset per cell), searched shell by shell (the cells at
// Chebyshev distance r from x's cell) and stopped as soon as the best distance found is no more
// than the distance from x to the nearest cell not yet searched (outside the (2r+1)^3 block). A
// grid that would exceed max_cells is made coarser (h doubled): the result stays exact.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace studio::offline::testing {

class PointIndex {
 public:
  PointIndex(const std::vector<Eigen::Vector3d>& points, double h, int max_shells = 64,
             std::size_t max_cells = std::size_t(1) << 23);
  double nearest(const Eigen::Vector3d& x) const;
  double cell() const { return h_; }

 private:
  double h_;
  int max_shells_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<uint32_t> start_;        // per cell (x fastest), + 1: points of cell k are
  std::vector<Eigen::Vector3d> pts_;   // pts_[start_[k] .. start_[k + 1])
};

}  // namespace studio::offline::testing
