#include "hull/visibility.h"

#include <algorithm>
#include <string>
#include <vector>

#include "frustum.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

Expected<Coverage> coverage(const GridSpec& grid, std::span<const Camera> cameras, int min_views) {
  if (auto ok = grid.validate(); !ok) return std::unexpected(ok.error());
  CutOptions policy;
  policy.min_views = min_views;
  if (auto ok = policy.validate(); !ok) return std::unexpected(ok.error());
  Coverage out;
  out.cameras = int(cameras.size());
  out.min_views = policy.required_views(cameras.size());
  std::vector<detail::Frustum> frusta;
  for (const Camera& c : cameras) frusta.push_back(detail::Frustum::of(c));
  const double t0 = grid.t_min(), t1 = grid.t_max();
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  d[grid.a()] = 1;
  std::vector<detail::Range> ranges(frusta.size()), pieces;
  std::vector<std::pair<double, int>> events;
  double seen = 0, enough = 0;
  for (int j = 0; j < grid.cells_v; ++j)
    for (int i = 0; i < grid.cells_u; ++i) {
      const Eigen::Vector3d o = grid.point(i, j, 0);
      for (std::size_t k = 0; k < frusta.size(); ++k) ranges[k] = frusta[k].seen(o, d, t0, t1);
      for (const auto& [need, sum] : {std::pair{1, &seen}, std::pair{out.min_views, &enough}}) {
        pieces.clear();
        detail::at_least(ranges, need, t0, t1, &events, &pieces);
        for (const auto& p : pieces) *sum += p.hi - p.lo;
      }
    }
  const double total = double(grid.columns()) * (t1 - t0);
  out.unseen = std::clamp(1 - seen / total, 0.0, 1.0);
  out.below_min_views = std::clamp(1 - enough / total, 0.0, 1.0);
  return out;
}

}  // namespace studio::hull
