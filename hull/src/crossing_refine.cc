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
// wholly inside the silhouette: in every pixel row it crosses, its part in that row lies within
// one run of `mask`, so cutting it with that view would keep it whole (pixel (x, y) covers
// [x-0.5, x+0.5) x [y-0.5, y+0.5), the row walker's convention). Both ends in front of the camera
// put the whole segment in front, where its image is the straight segment between the ends'.
// False means "cut to find out". A crossing segment is one cell long (2-3 px in the studio's
// cameras), so it crosses one to three rows.
// h0, h1: the ends' homogeneous images.
bool inside_runs(const Eigen::Vector3d& h0, const Eigen::Vector3d& h1, const RunMask& mask) {
  if (!(h0.z() > 0) || !(h1.z() > 0)) return false;
  const double w0 = 1 / h0.z(), w1 = 1 / h1.z();
  const double u0 = h0.x() * w0, v0 = h0.y() * w0;
  const double u1 = h1.x() * w1, v1 = h1.y() * w1;
  const double ylo = std::floor(std::min(v0, v1) + 0.5), yhi = std::floor(std::max(v0, v1) + 0.5);
  if (ylo < 0 || yhi >= mask.height() || yhi - ylo > 8) return false;
  const double du = u1 - u0, dv = v1 - v0;
  const double inv_dv = ylo == yhi ? 0 : 1 / dv;  // one row: the whole segment is in it
  for (int y = int(ylo); y <= int(yhi); ++y) {
    // The segment's part in the row's band [y - 0.5, y + 0.5): s in [sa, sb] of [0, 1].
    double sa = 0, sb = 1;
    if (inv_dv != 0) {
      const double a = (y - 0.5 - v0) * inv_dv, b = a + inv_dv;
      sa = std::max(0.0, std::min(a, b)), sb = std::min(1.0, std::max(a, b));
    }
    const double ua = u0 + sa * du, ub = u0 + sb * du;
    const double lo_u = std::floor(std::min(ua, ub) + 0.5),
                 hi_u = std::floor(std::max(ua, ub) + 0.5);
    if (lo_u < 0 || hi_u >= mask.width()) return false;
    const int lo = int(lo_u), hi = int(hi_u);
    const auto runs = mask.row(y);
    // The first run ending after lo must also start at or before it and reach past hi.
    const auto it = std::upper_bound(runs.begin(), runs.end(), lo,
                                     [](int x, const Run& r) { return x < r.end; });
    if (it == runs.end() || it->begin > lo || hi >= it->end) return false;
  }
  return true;
}

}  // namespace

Expected<void> refine_crossings(Mesh& mesh, const SegmentSet& set, std::span<const View> views,
                                const CutOptions& options, bool normals) {
  if (auto ok = options.validate(); !ok) return ok;
  const GridSpec& g = set.grid();
  const int ua = g.u(), va = g.v(), aa = g.a();
  const double du = g.du(), dv = g.dv();
  const double two_du = 2 / du, two_dv = 2 / dv;  // lattice lines are at half cells
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
  // Distortion-free cameras get a cheap whole-segment test before the cut (inside_runs).
  // The image of a point on an edge is affine in it: h = P (from, 1) + s P (d, 0).
  std::vector<std::optional<Eigen::Matrix<double, 3, 4>>> straight(views.size());
  for (std::size_t v = 0; v < views.size(); ++v)
    if (views[v].camera->distortion.is_identity())
      straight[v] = views[v].camera->projection_matrix();
  const int edge_axis[2] = {ua, va};
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
      const int x2 = int(std::lround((p[ua] - g.box_min[ua]) * two_du + 1));
      const int y2 = int(std::lround((p[va] - g.box_min[va]) * two_dv + 1));
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
      const double sign = first_inside ? 1 : -1;
      for (std::size_t v = 0; v < views.size(); ++v) {
        if (a.size() == 1 && straight[v]) {
          const Eigen::Matrix<double, 3, 4>& P = *straight[v];
          const Eigen::Vector3d h = P.leftCols<3>() * from + P.col(3);
          const Eigen::Vector3d e = sign * P.col(edge_axis[k]);
          if (inside_runs(h + double(a[0].lo) * e, h + double(a[0].hi) * e, *views[v].mask))
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
  if (normals)
    compute_normals(mesh);
  else
    mesh.normals.clear();
  return {};
}

}  // namespace studio::hull
