#include "testing/point_index.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace studio::offline::testing {

PointIndex::PointIndex(const std::vector<Eigen::Vector3d>& points, double h, int max_shells,
                       std::size_t max_cells)
    : h_(h), max_shells_(max_shells) {
  if (points.empty()) return;
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const auto& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  origin_ = lo;
  const auto dims_for = [&](double cell) {
    const Eigen::Vector3d n = ((hi - lo) / cell).array().floor() + 1;
    return n;
  };
  while (dims_for(h_).prod() > double(max_cells)) h_ *= 2;
  dims_ = dims_for(h_).cast<int>();
  const auto index = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3i c = ((p - origin_) / h_).array().floor().cast<int>().min(dims_.array() - 1);
    return (std::size_t(c.z()) * std::size_t(dims_.y()) + std::size_t(c.y())) *
               std::size_t(dims_.x()) +
           std::size_t(c.x());
  };
  const std::size_t cells = std::size_t(dims_.prod());
  start_.assign(cells + 1, 0);
  std::vector<std::size_t> cell_of(points.size());
  for (std::size_t n = 0; n < points.size(); ++n) ++start_[(cell_of[n] = index(points[n])) + 1];
  for (std::size_t k = 0; k < cells; ++k) start_[k + 1] += start_[k];
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  pts_.resize(points.size());
  for (std::size_t n = 0; n < points.size(); ++n) pts_[fill[cell_of[n]]++] = points[n];
}

double PointIndex::nearest(const Eigen::Vector3d& x) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (pts_.empty()) return kInf;
  // x's cell, possibly outside the grid (clamped far out so that the int arithmetic is safe).
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((x[a] - origin_[a]) / h_);
    c[a] = int(std::clamp(f, -1e6, 1e6));
  }
  double best2 = kInf;
  const auto scan = [&](int x0, int x1, int y, int z) {  // cells x0..x1 (inclusive) of row (y, z)
    const std::size_t row = (std::size_t(z) * std::size_t(dims_.y()) + std::size_t(y)) *
                            std::size_t(dims_.x());
    for (uint32_t n = start_[row + std::size_t(x0)]; n < start_[row + std::size_t(x1) + 1]; ++n)
      best2 = std::min(best2, (pts_[n] - x).squaredNorm());
  };
  for (int r = 0; r < max_shells_; ++r) {
    // The cells of shell r (Chebyshev distance r from c) inside the grid: where neither dz nor
    // dy is on the shell, only dx = -r and dx = r are.
    const int z0 = std::max(c.z() - r, 0), z1 = std::min(c.z() + r, dims_.z() - 1);
    const int y0 = std::max(c.y() - r, 0), y1 = std::min(c.y() + r, dims_.y() - 1);
    const int xa = std::max(c.x() - r, 0), xb = std::min(c.x() + r, dims_.x() - 1);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y) {
        const bool face = std::abs(z - c.z()) == r || std::abs(y - c.y()) == r;
        if (face) {
          if (xa <= xb) scan(xa, xb, y, z);
        } else {
          if (c.x() - r >= 0 && c.x() - r < dims_.x()) scan(c.x() - r, c.x() - r, y, z);
          if (r > 0 && c.x() + r >= 0 && c.x() + r < dims_.x()) scan(c.x() + r, c.x() + r, y, z);
        }
      }
    // Every cell not searched yet lies outside the block c +- r: at least `bound` from x.
    bool whole_grid = true;
    double bound = kInf;
    for (int a = 0; a < 3; ++a) {
      whole_grid = whole_grid && c[a] - r <= 0 && c[a] + r >= dims_[a] - 1;
      const double lo = origin_[a] + (c[a] - r) * h_, hi = origin_[a] + (c[a] + r + 1) * h_;
      bound = std::min(bound, std::min(x[a] - lo, hi - x[a]));
    }
    if (whole_grid) break;
    if (best2 != kInf && std::sqrt(best2) <= bound * (1 - 1e-12)) break;
  }
  return std::sqrt(best2);
}

}  // namespace studio::offline::testing
