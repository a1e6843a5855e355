#include "frustum.h"

#include <algorithm>

namespace studio::hull::detail {

Rect ideal_border_box(const Camera& camera) {
  const int W = camera.width, H = camera.height;
  const Intrinsics& k = camera.intrinsics;
  const auto to_ideal = [&](const Eigen::Vector2d& obs) -> Eigen::Vector2d {
    const double yn = (obs.y() - k.cy) / k.fy;
    const double xn = (obs.x() - k.cx - k.skew * yn) / k.fx;
    const Eigen::Vector2d d = undistort(camera.distortion, {xn, yn});
    return {k.fx * d.x() + k.skew * d.y() + k.cx, k.fy * d.y() + k.cy};
  };
  double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
  for (int s = 0; s <= 64; ++s) {
    const double fu = -0.5 + W * s / 64.0, fv = -0.5 + H * s / 64.0;
    for (const Eigen::Vector2d& p : {Eigen::Vector2d(fu, -0.5), Eigen::Vector2d(fu, H - 0.5),
                                     Eigen::Vector2d(-0.5, fv), Eigen::Vector2d(W - 0.5, fv)}) {
      const Eigen::Vector2d q = to_ideal(p);
      u0 = std::min(u0, q.x()), u1 = std::max(u1, q.x());
      v0 = std::min(v0, q.y()), v1 = std::max(v1, q.y());
    }
  }
  return {u0, u1, v0, v1};
}

Frustum Frustum::of(const Camera& camera) {
  Frustum f;
  f.P = camera.projection_matrix();
  f.rect = camera.distortion.is_identity()
               ? Rect{-0.5, camera.width - 0.5, -0.5, camera.height - 0.5}
               : ideal_border_box(camera);
  return f;
}

void at_least(std::span<const Range> ranges, int need, double lo, double hi,
              std::vector<std::pair<double, int>>* events, std::vector<Range>* out) {
  if (!(lo < hi)) return;
  if (need <= 0) {
    out->push_back({lo, hi});
    return;
  }
  // Starts in events[0, n), ends in events[n, 2n), each sorted by insertion (a few dozen views),
  // then merged with ends before starts at equal t (touching ranges do not overlap).
  events->resize(2 * ranges.size());
  std::pair<double, int>* e = events->data();
  std::size_t n = 0;
  for (const Range& r : ranges) {
    const double a = std::max(lo, r.lo), b = std::min(hi, r.hi);
    if (!(a < b)) continue;
    std::size_t k = n;
    for (; k > 0 && e[k - 1].first > a; --k) e[k] = e[k - 1];
    e[k].first = a;
    ++n;
  }
  if (n < std::size_t(need)) return;
  std::pair<double, int>* f = e + n;
  std::size_t m = 0;
  for (const Range& r : ranges) {
    const double a = std::max(lo, r.lo), b = std::min(hi, r.hi);
    if (!(a < b)) continue;
    std::size_t k = m;
    for (; k > 0 && f[k - 1].first > b; --k) f[k] = f[k - 1];
    f[k].first = b;
    ++m;
  }
  int count = 0;
  double open = 0;
  std::size_t i = 0, j = 0;
  while (j < m) {
    const bool start = i < n && e[i].first < f[j].first;
    const double t = start ? e[i++].first : f[j++].first;
    const bool was = count >= need;
    count += start ? 1 : -1;
    const bool is = count >= need;
    if (!was && is) {
      open = t;
    } else if (was && !is && open < t) {
      if (!out->empty() && out->back().hi >= open) {
        out->back().hi = t;
      } else {
        out->push_back({open, t});
      }
    }
  }
}

void intersect(std::span<const Interval> a, std::span<const Range> b, std::vector<Interval>* out) {
  std::size_t p = 0;
  const std::size_t begin = out->size();
  for (const Interval& iv : a) {
    while (p < b.size() && b[p].hi <= iv.lo) ++p;
    for (std::size_t q = p; q < b.size() && b[q].lo < iv.hi; ++q) {
      const float lo = float(std::max<double>(iv.lo, b[q].lo));
      const float hi = float(std::min<double>(iv.hi, b[q].hi));
      if (!(hi > lo)) continue;
      if (out->size() > begin && out->back().hi >= lo) {
        out->back().hi = std::max(out->back().hi, hi);
      } else {
        out->push_back({lo, hi});
      }
    }
  }
}

}  // namespace studio::hull::detail
