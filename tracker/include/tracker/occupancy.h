#pragma once
// A dense occupancy grid: the input of the head tracker's template filter (TCSVT 2004 §IV-D).
//
// Geometry: voxel (x, y, z) covers [origin + (x, y, z) ∘ voxel, origin + (x+1, y+1, z+1) ∘ voxel)
// in the studio frame (metres, y up). Each voxel holds the fraction of it that is occupied, in
// units of 1/255 (kFull = fully occupied), so a visual hull cut with continuous segments keeps
// its sub-voxel extent along the segment axis. Everything outside the grid is empty: a grid may
// (and, for speed, should) cover only the occupied part of the studio.
//
// Storage order: x slowest, then z, then y fastest, so a column along y (the studio's up, the
// default segment axis of the hull) is contiguous.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace studio::tracker {

class OccupancyGrid {
 public:
  static constexpr int kFull = 255;

  OccupancyGrid() = default;
  // dims must be non-negative and voxel positive (programming errors otherwise).
  OccupancyGrid(const Eigen::Vector3d& origin, const Eigen::Vector3d& voxel,
                const Eigen::Vector3i& dims);

  const Eigen::Vector3d& origin() const { return origin_; }
  const Eigen::Vector3d& voxel() const { return voxel_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  std::size_t size() const { return data_.size(); }
  bool empty() const { return data_.empty(); }

  std::size_t index(int x, int y, int z) const {
    return (std::size_t(x) * std::size_t(dims_.z()) + std::size_t(z)) * std::size_t(dims_.y()) +
           std::size_t(y);
  }
  bool inside(int x, int y, int z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < dims_.x() && y < dims_.y() && z < dims_.z();
  }
  uint8_t at(int x, int y, int z) const { return data_[index(x, y, z)]; }
  uint8_t& at(int x, int y, int z) { return data_[index(x, y, z)]; }
  // Contiguous column along y at (x, z).
  std::span<uint8_t> column(int x, int z) {
    return {data_.data() + index(x, 0, z), size_t(dims_.y())};
  }
  std::span<const uint8_t> column(int x, int z) const {
    return {data_.data() + index(x, 0, z), size_t(dims_.y())};
  }
  std::span<const uint8_t> data() const { return data_; }
  std::span<uint8_t> data() { return data_; }

  // Studio-frame point at continuous voxel coordinates (voxel (i,j,k) spans [i, i+1) etc.).
  Eigen::Vector3d point(const Eigen::Vector3d& voxel_coords) const {
    return origin_ + voxel_coords.cwiseProduct(voxel_);
  }
  Eigen::Vector3d voxel_coords(const Eigen::Vector3d& point) const {
    return (point - origin_).cwiseQuotient(voxel_);
  }
  double voxel_volume() const { return voxel_.prod(); }
  // Sum of occupancy in m³.
  double occupied_volume() const;

  void clear();
  // Re-shapes to new geometry with every voxel empty, reusing the storage.
  void reset(const Eigen::Vector3d& origin, const Eigen::Vector3d& voxel,
             const Eigen::Vector3i& dims);
  // Smallest sub-grid (same lattice) holding every occupied voxel; an empty grid if none.
  OccupancyGrid cropped_to_occupied() const;

 private:
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d voxel_ = Eigen::Vector3d::Ones();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<uint8_t> data_;
};

// A grid covering the axis-aligned box [box_min, box_max] with `columns` voxels along the wider
// of x and z and the same (cubic) voxel size on every axis, rounded up to whole voxels.
OccupancyGrid make_grid(const Eigen::Vector3d& box_min, const Eigen::Vector3d& box_max,
                        int columns);

}  // namespace studio::tracker
