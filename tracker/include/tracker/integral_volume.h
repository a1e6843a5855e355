#pragma once
// A 3-D summed-area table (integral volume) of an OccupancyGrid: the occupancy of any
// axis-aligned voxel box in O(1), eight look-ups (TCSVT 2004 §IV-D counts a1, a2 per box; the
// table makes the whole-volume template search affordable).
//
// S(x, y, z) = sum of occupancy over voxels [0, x) x [0, y) x [0, z); table dims = grid dims + 1,
// stored x slowest, then z, then y (as the grid). Counts are exact integers in units of 1/255
// voxel (OccupancyGrid::kFull). Grids up to kMaxVoxels voxels (int32 sums cannot overflow).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "tracker/occupancy.h"

namespace studio::tracker {

class IntegralVolume {
 public:
  static constexpr std::size_t kMaxVoxels = (std::size_t(1) << 31) / 256;

  IntegralVolume() = default;
  explicit IntegralVolume(const OccupancyGrid& grid) { build(grid); }
  // Rebuilds for `grid`, reusing memory. The grid must hold at most kMaxVoxels voxels.
  void build(const OccupancyGrid& grid);

  const Eigen::Vector3i& dims() const { return dims_; }
  // Occupancy over voxels [lo, hi) (per axis, exclusive upper bound), clipped to the grid;
  // 0 for an empty box. Units: 1/255 voxel.
  int64_t count(Eigen::Vector3i lo, Eigen::Vector3i hi) const {
    lo = lo.cwiseMax(0);
    hi = hi.cwiseMin(dims_);
    if ((hi.array() <= lo.array()).any()) return 0;
    const int32_t* s = table_.data();
    const std::size_t x0 = std::size_t(lo.x()) * sx_, x1 = std::size_t(hi.x()) * sx_;
    const std::size_t z0 = std::size_t(lo.z()) * sz_, z1 = std::size_t(hi.z()) * sz_;
    const std::size_t y0 = std::size_t(lo.y()), y1 = std::size_t(hi.y());
    const int64_t a =
        int64_t(s[x1 + z1 + y1]) - s[x0 + z1 + y1] - s[x1 + z0 + y1] + s[x0 + z0 + y1];
    const int64_t b =
        int64_t(s[x1 + z1 + y0]) - s[x0 + z1 + y0] - s[x1 + z0 + y0] + s[x0 + z0 + y0];
    return a - b;
  }
  int64_t total() const { return count({0, 0, 0}, dims_); }

 private:
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::size_t sx_ = 0, sz_ = 0;  // strides of x and z in the table
  std::vector<int32_t> table_;
};

}  // namespace studio::tracker
