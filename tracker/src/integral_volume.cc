#include "tracker/integral_volume.h"

#include <cassert>

namespace studio::tracker {

void IntegralVolume::build(const OccupancyGrid& grid) {
  assert(grid.size() <= kMaxVoxels);
  const Eigen::Vector3i n = grid.dims();
  dims_ = n;
  const std::size_t ny1 = std::size_t(n.y()) + 1, nz1 = std::size_t(n.z()) + 1;
  sz_ = ny1;
  sx_ = ny1 * nz1;
  table_.assign(sx_ * (std::size_t(n.x()) + 1), 0);
  int32_t* s = table_.data();
  // Plane x = 0 and row z = 0 of every plane stay zero. Each row: running sum along y of the
  // column, plus the row below in z (already the sum over [0, z) x [0, y)), plus the plane
  // before in x, minus their overlap: the standard recurrence done row by row.
  for (int x = 0; x < n.x(); ++x) {
    int32_t* plane = s + (std::size_t(x) + 1) * sx_;
    const int32_t* prev_plane = s + std::size_t(x) * sx_;
    for (int z = 0; z < n.z(); ++z) {
      int32_t* row = plane + (std::size_t(z) + 1) * sz_;
      const int32_t* row_zm = plane + std::size_t(z) * sz_;
      const int32_t* prow = prev_plane + (std::size_t(z) + 1) * sz_;
      const int32_t* prow_zm = prev_plane + std::size_t(z) * sz_;
      const auto col = grid.column(x, z);
      int32_t run = 0;
      row[0] = 0;
      for (int y = 0; y < n.y(); ++y) {
        run += col[std::size_t(y)];
        row[y + 1] = run + row_zm[y + 1] + prow[y + 1] - prow_zm[y + 1];
      }
    }
  }
}

}  // namespace studio::tracker
