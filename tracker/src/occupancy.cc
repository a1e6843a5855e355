#include "tracker/occupancy.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace studio::tracker {

OccupancyGrid::OccupancyGrid(const Eigen::Vector3d& origin, const Eigen::Vector3d& voxel,
                             const Eigen::Vector3i& dims)
    : origin_(origin), voxel_(voxel), dims_(dims) {
  assert((dims.array() >= 0).all() && (voxel.array() > 0).all());
  data_.assign(std::size_t(dims.x()) * std::size_t(dims.y()) * std::size_t(dims.z()), 0);
}

double OccupancyGrid::occupied_volume() const {
  uint64_t sum = 0;
  for (uint8_t v : data_) sum += v;
  return double(sum) / kFull * voxel_volume();
}

void OccupancyGrid::reset(const Eigen::Vector3d& origin, const Eigen::Vector3d& voxel,
                          const Eigen::Vector3i& dims) {
  assert((dims.array() >= 0).all() && (voxel.array() > 0).all());
  origin_ = origin;
  voxel_ = voxel;
  dims_ = dims;
  data_.assign(std::size_t(dims.x()) * std::size_t(dims.y()) * std::size_t(dims.z()), 0);
}

void OccupancyGrid::clear() { std::fill(data_.begin(), data_.end(), uint8_t{0}); }

OccupancyGrid OccupancyGrid::cropped_to_occupied() const {
  Eigen::Vector3i lo = dims_, hi = Eigen::Vector3i::Constant(-1);
  for (int x = 0; x < dims_.x(); ++x) {
    for (int z = 0; z < dims_.z(); ++z) {
      const auto col = column(x, z);
      const auto first = std::find_if(col.begin(), col.end(), [](uint8_t v) { return v != 0; });
      if (first == col.end()) continue;
      const auto last = std::find_if(col.rbegin(), col.rend(), [](uint8_t v) { return v != 0; });
      lo = lo.cwiseMin(Eigen::Vector3i(x, int(first - col.begin()), z));
      hi = hi.cwiseMax(Eigen::Vector3i(x, int(col.rend() - last) - 1, z));
    }
  }
  if (hi.x() < 0) return OccupancyGrid(origin_, voxel_, Eigen::Vector3i::Zero());
  const Eigen::Vector3i n = hi - lo + Eigen::Vector3i::Ones();
  OccupancyGrid out(point(lo.cast<double>()), voxel_, n);
  for (int x = 0; x < n.x(); ++x) {
    for (int z = 0; z < n.z(); ++z) {
      const auto src =
          column(x + lo.x(), z + lo.z()).subspan(std::size_t(lo.y()), std::size_t(n.y()));
      std::copy(src.begin(), src.end(), out.column(x, z).begin());
    }
  }
  return out;
}

OccupancyGrid make_grid(const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max,
                        int columns) {
  assert(columns > 0 && (box_max.array() > box_min.array()).all());
  const Eigen::Vector3d extent = box_max - box_min;
  const double v = std::max(extent.x(), extent.z()) / columns;
  Eigen::Vector3i dims;
  for (int a = 0; a < 3; ++a) dims[a] = std::max(1, int(std::ceil(extent[a] / v - 1e-9)));
  return OccupancyGrid(box_min, Eigen::Vector3d::Constant(v), dims);
}

}  // namespace studio::tracker
