#include "hull/crossing_refine.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <thread>
#include <vector>

namespace studio::hull {
namespace {

// Whether the column holds t just below (below = true) or just above t (intervals half-open).
bool occupied(std::span<const Interval> col, float t, bool below) {
  for (const Interval& iv : col) {
    if (below ? (iv.lo < t && t <= iv.hi) : (iv.lo <= t && t < iv.hi)) return true;
  }
  return false;
}

// The largest end point of either column strictly below t (or above, for below = false).
double neighbour_event(std::span<const Interval> a, std::span<const Interval> b, float t,
                       bool below, double fallback) {
  double best = fallback;
  for (auto col : {a, b}) {
    for (const Interval& iv : col) {
      for (const float e : {iv.lo, iv.hi}) {
        if (below && e < t) best = std::max(best, double(e));
        if (!below && e > t) best = std::min(best, double(e));
      }
    }
  }
  return best;
}

// Whether the straight image of the segment p0-p1 (a distortion-free camera, P = K [R | t]) lies
// in one pixel row and within one run of `mask`, i.e. wholly inside the silhouette: cutting it
// with that view would keep it whole (pixel (x, y) covers [x-0.5, x+0.5) x [y-0.5, y+0.5), the
// row walker's convention). False means "cut to find out".
bool inside_one_run(const Eigen::Matrix<double, 3, 4>& P, const RunMask& mask,
                    const Eigen::Vector3d& p0, const Eigen::Vector3d& p1) {
  const Eigen::Vector3d h0 = P * p0.homogeneous(), h1 = P * p1.homogeneous();
  if (!(h0.z() > 0) || !(h1.z() > 0)) return false;
  const double y0 = std::floor(h0.y() / h0.z() + 0.5), y1 = std::floor(h1.y() / h1.z() + 0.5);
  if (y0 != y1 || y0 < 0 || y0 >= mask.height()) return false;
  const double xa = std::floor(h0.x() / h0.z() + 0.5), xb = std::floor(h1.x() / h1.z() + 0.5);
  const double lo = std::min(xa, xb), hi = std::max(xa, xb);
  if (lo < 0 || hi >= mask.width()) return false;
  const auto runs = mask.row(int(y0));
  // The first run ending after lo must also start at or before it and reach past hi.
  const auto it = std::upper_bound(runs.begin(), runs.end(), lo,
                                   [](double x, const Run& r) { return x < double(r.end); });
  return it != runs.end() && double(it->begin) <= lo && hi < double(it->end);
}

}  // namespace

Expected<void> refine_crossings(Mesh& mesh, const SegmentSet& set, std::span<const View> views,
                                const CutOptions& options) {
  if (auto ok = options.validate(); !ok) return ok;
  const GridSpec& g = set.grid();
  const int ua = g.u(), va = g.v(), aa = g.a();
  const double du = g.du(), dv = g.dv();
  const Eigen::AlignedBox3d domain(g.box_min, g.box_max);
  // Lines along e_u and along e_v: two pencils through points at infinity.
  std::vector<PreparedView> along[2];
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector4d X = Eigen::Vector4d::Zero();
    X[k == 0 ? ua : va] = 1;
    for (const View& v : views) {
      auto p = PreparedView::create(*v.camera, *v.mask, X, options, &domain);
      if (!p) return std::unexpected(p.error());
      along[k].push_back(std::move(*p));
    }
  }
  // Distortion-free cameras get a cheap whole-segment test before the cut (inside_one_run).
  std::vector<std::optional<Eigen::Matrix<double, 3, 4>>> straight(views.size());
  for (std::size_t v = 0; v < views.size(); ++v)
    if (views[v].camera->distortion.is_identity())
      straight[v] = views[v].camera->projection_matrix();
  const auto column = [&](int i, int j) -> std::span<const Interval> {
    if (i < 0 || j < 0 || i >= g.cells_u || j >= g.cells_v) return {};
    return set.column(i, j);
  };
  // Vertices are independent: split them over options.threads workers.
  const auto refine_range = [&](std::size_t first, std::size_t last) {
    std::vector<Interval> a, b;
    CutScratch scratch;
    for (std::size_t vi = first; vi < last; ++vi) {
      Eigen::Vector3f& p = mesh.vertices[vi];
      // Lattice line in doubled coordinates (see segment_mesh.cc): column (i, j) is (2i+2, 2j+2).
      const int x2 = int(std::lround((p[ua] - g.box_min[ua]) / du * 2 + 1));
      const int y2 = int(std::lround((p[va] - g.box_min[va]) / dv * 2 + 1));
      const bool odd_x = (x2 & 1) != 0, odd_y = (y2 & 1) != 0;
      if (odd_x == odd_y) continue;  // a column or a cell centre
      const int k = odd_x ? 0 : 1;   // edge along u or along v
      const int i0 = odd_x ? (x2 - 3) / 2 : (x2 - 2) / 2;
      const int j0 = odd_x ? (y2 - 2) / 2 : (y2 - 3) / 2;
      const int i1 = i0 + (odd_x ? 1 : 0), j1 = j0 + (odd_x ? 0 : 1);
      const auto c0 = column(i0, j0), c1 = column(i1, j1);
      const float t = p[aa];
      const bool b0 = occupied(c0, t, true), b1 = occupied(c1, t, true);
      const bool a0 = occupied(c0, t, false), a1 = occupied(c1, t, false);
      double te;
      bool first_inside;
      if (b0 != b1 && a0 != a1 && b0 == a0) {
        te = t, first_inside = b0;
      } else if (b0 != b1) {
        const double prev = neighbour_event(c0, c1, t, true, g.t_min());
        te = t - std::min(1e-3, 0.5 * (t - prev)), first_inside = b0;
      } else if (a0 != a1) {
        const double next = neighbour_event(c0, c1, t, false, g.t_max());
        te = t + std::min(1e-3, 0.5 * (next - t)), first_inside = a0;
      } else {
        continue;
      }
      // From the inside column towards the outside one.
      const double step = k == 0 ? du : dv;
      const Eigen::Vector3d from = g.point(first_inside ? i0 : i1, first_inside ? j0 : j1, te);
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[k == 0 ? ua : va] = first_inside ? 1 : -1;
      a.assign(1, Interval{0.f, float(step)});
      for (std::size_t v = 0; v < views.size(); ++v) {
        if (a.size() == 1 && straight[v] &&
            inside_one_run(*straight[v], *views[v].mask, from + double(a[0].lo) * d,
                           from + double(a[0].hi) * d)) {
          continue;  // this view keeps the piece whole
        }
        b.clear();
        along[k][v].cut_line(from, d, a, &b, &scratch);
        std::swap(a, b);
        if (a.empty()) break;
      }
      // The surviving piece at the inside column; the half-cell guess when quantisation lost it.
      double s = 0.5 * step;
      if (!a.empty() && a.front().lo <= 0.02 * step) s = a.front().hi;
      s = std::clamp(s, 0.02 * step, 0.98 * step);
      const double at = from[k == 0 ? ua : va] + (first_inside ? s : -s);
      p[k == 0 ? ua : va] = float(at);
    }
  };
  const std::size_t n = mesh.vertices.size();
  const std::size_t workers =
      std::clamp<std::size_t>(std::size_t(options.threads), 1, std::max<std::size_t>(n / 4096, 1));
  {
    std::vector<std::jthread> pool;
    for (std::size_t w = 1; w < workers; ++w)
      pool.emplace_back(refine_range, n * w / workers, n * (w + 1) / workers);
    refine_range(0, n / workers);
  }
  compute_normals(mesh);
  return {};
}

}  // namespace studio::hull
