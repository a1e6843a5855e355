#include "tracker/segment_raster.h"

#include <algorithm>
#include <cmath>

namespace studio::tracker {

void rasterise(const hull::SegmentSet& set, OccupancyGrid* grid) {
  const hull::GridSpec& spec = set.grid();
  const int a = spec.a(), u = spec.u(), v = spec.v();
  const double du = spec.du(), dv = spec.dv();
  const double dt = std::min(du, dv);
  const double t0 = spec.t_min();
  const int nt = std::max(1, int(std::ceil((spec.t_max() - t0) / dt - 1e-9)));

  // Occupied extent: columns with intervals, and the t range they span.
  int i_lo = spec.cells_u, i_hi = -1, j_lo = spec.cells_v, j_hi = -1;
  double t_lo = spec.t_max(), t_hi = t0;
  for (int j = 0; j < spec.cells_v; ++j)
    for (int i = 0; i < spec.cells_u; ++i) {
      const auto col = set.column(i, j);
      if (col.empty()) continue;
      i_lo = std::min(i_lo, i), i_hi = std::max(i_hi, i);
      j_lo = std::min(j_lo, j), j_hi = std::max(j_hi, j);
      t_lo = std::min(t_lo, double(col.front().lo));
      t_hi = std::max(t_hi, double(col.back().hi));
    }
  Eigen::Vector3d voxel;
  voxel[u] = du, voxel[v] = dv, voxel[a] = dt;
  if (i_hi < 0 || t_hi <= t_lo) {
    grid->reset(spec.box_min, voxel, Eigen::Vector3i::Zero());
    return;
  }
  const int k_lo = std::clamp(int(std::floor((t_lo - t0) / dt)), 0, nt - 1);
  const int k_hi = std::clamp(int(std::ceil((t_hi - t0) / dt)), k_lo + 1, nt);
  Eigen::Vector3d origin;
  origin[u] = spec.box_min[u] + i_lo * du;
  origin[v] = spec.box_min[v] + j_lo * dv;
  origin[a] = t0 + k_lo * dt;
  Eigen::Vector3i dims;
  dims[u] = i_hi - i_lo + 1, dims[v] = j_hi - j_lo + 1, dims[a] = k_hi - k_lo;
  grid->reset(origin, voxel, dims);

  const double tk0 = origin[a];
  const int nk = dims[a];
  // Along the continuous axis, add each interval's coverage to the voxels it crosses.
  for (int j = j_lo; j <= j_hi; ++j)
    for (int i = i_lo; i <= i_hi; ++i) {
      const auto col = set.column(i, j);
      if (col.empty()) continue;
      Eigen::Vector3i cell;
      cell[u] = i - i_lo, cell[v] = j - j_lo, cell[a] = 0;
      // Address of voxel k of this line (stride 1 when the continuous axis is y).
      const std::size_t base = grid->index(cell.x(), cell.y(), cell.z());
      Eigen::Vector3i step = Eigen::Vector3i::Zero();
      step[a] = 1;
      const std::size_t stride = grid->index(step.x(), step.y(), step.z()) - grid->index(0, 0, 0);
      uint8_t* line = grid->data().data() + base;
      const auto add = [&](int k, double fraction) {
        if (k < 0 || k >= nk || fraction <= 0) return;
        uint8_t& cellv = line[std::size_t(k) * stride];
        cellv = uint8_t(std::min(int(OccupancyGrid::kFull),
                                 int(cellv) + int(std::lround(fraction * OccupancyGrid::kFull))));
      };
      for (const hull::Interval& iv : col) {
        const double lo = (iv.lo - tk0) / dt, hi = (iv.hi - tk0) / dt;
        const int kl = int(std::floor(lo)), kh = int(std::floor(hi));
        if (kl == kh) {
          add(kl, hi - lo);
          continue;
        }
        add(kl, kl + 1 - lo);
        for (int k = std::max(kl + 1, 0); k < std::min(kh, nk); ++k)
          line[std::size_t(k) * stride] = OccupancyGrid::kFull;
        add(kh, hi - kh);
      }
    }
}

}  // namespace studio::tracker
