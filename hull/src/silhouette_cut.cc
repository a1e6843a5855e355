#include "hull/silhouette_cut.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <thread>

#include "frustum.h"
#include "grid_cut.h"

namespace studio::hull {
namespace {

using Vec3 = Eigen::Vector3d;

using detail::clip_halfline;
using detail::in_rect;
using detail::Range;
using detail::Rect;

// Pieces of [ta, tb] where the straight image piece A + t B (homogeneous, w > 0, inside the
// image) lies on a foreground pixel square. Walks the rows it crosses; appends to *out. Every
// image constraint is a half-line in t (u >= a  <=>  (A0 - a A2) + t (B0 - a B2) >= 0 while
// w > 0), which stays exact where the projective map t -> image wraps through infinity.
void walk_rows(const Vec3& A, const Vec3& B, double ta, double tb, const RunMask& m,
               std::vector<Range>* out) {
  const auto U = [&](double t) { return (A[0] + t * B[0]) / (A[2] + t * B[2]); };
  const auto V = [&](double t) { return (A[1] + t * B[1]) / (A[2] + t * B[2]); };
  const double va = V(ta), vb = V(tb);
  const int H = m.height();
  const int y0 = std::clamp(int(std::floor(std::min(va, vb) + 0.5)), 0, H - 1);
  const int y1 = std::clamp(int(std::floor(std::max(va, vb) + 0.5)), 0, H - 1);
  for (int y = y0; y <= y1; ++y) {
    double r0 = ta, r1 = tb;
    clip_halfline(A[1] - (y - 0.5) * A[2], B[1] - (y - 0.5) * B[2], r0, r1);
    clip_halfline((y + 0.5) * A[2] - A[1], (y + 0.5) * B[2] - B[1], r0, r1);
    if (!(r0 < r1)) continue;
    const double ua = U(r0), ub = U(r1);
    const double umin = std::min(ua, ub), umax = std::max(ua, ub);
    const auto row = m.row(y);
    auto it = std::partition_point(row.begin(), row.end(),
                                   [&](const Run& r) { return r.end - 0.5 <= umin; });
    for (; it != row.end() && it->begin - 0.5 <= umax; ++it) {
      double s0 = r0, s1 = r1;
      const double a = it->begin - 0.5, b = it->end - 0.5;
      clip_halfline(A[0] - a * A[2], B[0] - a * B[2], s0, s1);
      clip_halfline(b * A[2] - A[0], b * B[2] - B[0], s0, s1);
      if (s0 < s1) out->push_back({s0, s1});
    }
  }
}

void sort_merge(std::vector<Range>* r, std::size_t from) {
  auto b = r->begin() + std::ptrdiff_t(from);
  std::sort(b, r->end(), [](const Range& x, const Range& y) { return x.lo < y.lo; });
  std::size_t w = from;
  for (std::size_t k = from; k < r->size(); ++k) {
    if (!((*r)[k].lo < (*r)[k].hi)) continue;
    if (w > from && (*r)[w - 1].hi >= (*r)[k].lo) {
      (*r)[w - 1].hi = std::max((*r)[w - 1].hi, (*r)[k].hi);
    } else {
      (*r)[w++] = (*r)[k];
    }
  }
  r->resize(w);
}

// Appends (sorted, disjoint) pieces as float intervals, merging those that touch after rounding.
void emit(const std::vector<Range>& keep, std::vector<Interval>* out, std::size_t out_begin) {
  for (const Range& r : keep) {
    const float lo = float(r.lo), hi = float(r.hi);
    if (!(hi > lo)) continue;
    if (out->size() > out_begin && out->back().hi >= lo) {
      out->back().hi = std::max(out->back().hi, hi);
    } else {
      out->push_back({lo, hi});
    }
  }
}

// Calls f(a, b) for every maximal range of A \ B (A, B sorted disjoint half-open int ranges).
template <class F>
void difference(const std::vector<std::pair<int, int>>& A,
                const std::vector<std::pair<int, int>>& B, F&& f) {
  std::size_t j = 0;
  for (const auto& [a0, a1] : A) {
    int x = a0;
    while (j < B.size() && B[j].second <= x) ++j;
    std::size_t k = j;
    while (x < a1) {
      if (k < B.size() && B[k].first < a1) {
        if (B[k].first > x) f(x, B[k].first);
        x = std::max(x, B[k].second);
        ++k;
      } else {
        f(x, a1);
        x = a1;
      }
    }
  }
}

Eigen::Vector2d ideal_to_observed(const Camera& c, const Eigen::Vector2d& ideal) {
  const Intrinsics& k = c.intrinsics;
  const double yn = (ideal.y() - k.cy) / k.fy;
  const double xn = (ideal.x() - k.cx - k.skew * yn) / k.fx;
  const Eigen::Vector2d d = distort(c.distortion, {xn, yn});
  return {k.fx * d.x() + k.skew * d.y() + k.cx, k.fy * d.y() + k.cy};
}

}  // namespace

Expected<void> CutOptions::validate() const {
  if (threads < 1 || threads > 64)
    return fail("threads: " + std::to_string(threads) + " (need 1..64)");
  if (min_views != kAllViews && (min_views < 0 || min_views > 64))
    return fail("min_views: " + std::to_string(min_views) + " (need 0..64 or all)");
  return {};
}

struct PreparedView::Impl {
  Camera camera;
  const RunMask* mask = nullptr;
  Eigen::Matrix<double, 3, 4> P;
  static constexpr bool keep_outside = true;  // the policy's min_views is applied by callers
  bool distorted = false;
  Rect image{};        // observed image rectangle (pixel-square edges)
  Rect ideal_image{};  // where the distortion model is trusted (ideal pixels)
  Rect seen_rect{};    // the policy's seeing rectangle (detail::Frustum)
  // Pencil bins.
  bool pencil = false;
  bool all_inside = false;  // the whole domain projects in front of the camera, inside the image
  Vec3 V = Vec3::Zero();
  double vref = 0, smin = 0, ds = 0.5, inv_ds = 2.0;
  int nbins = 0;
  std::vector<uint32_t> bin_start;
  std::vector<float> bin_v;                   // pairs (v0, v1) per run, in ideal pixel rows
  std::vector<std::pair<int, int>> occupied;  // maximal ranges [k0, k1) of non-empty bins

  double pencil_s(double u, double v) const {
    const double d0 = V[0] - V[2] * u, d1 = V[1] - V[2] * v;
    return u + d0 * (vref - v) / d1;
  }
  void build_pencil(const Eigen::Vector4d& X);
  void cut_pencil(const Vec3& A, const Vec3& B, std::span<const Interval> in,
                  std::vector<Range>* keep) const;
  void cut_walk(const Vec3& A, const Vec3& B, std::span<const Interval> in,
                std::vector<Range>* keep) const;
  void cut_walk_distorted(const Vec3& A, const Vec3& B, std::span<const Interval> in,
                          std::vector<Range>* keep) const;
};

void PreparedView::Impl::build_pencil(const Eigen::Vector4d& X) {
  const int W = mask->width(), H = mask->height();
  V = P * X;
  const double corners[4][2] = {{-0.5, -0.5}, {W - 0.5, -0.5}, {-0.5, H - 0.5}, {W - 0.5, H - 0.5}};
  int sign = 0;
  for (const auto& c : corners) {
    const double d0 = V[0] - V[2] * c[0], d1 = V[1] - V[2] * c[1];
    if (!(std::abs(d0) <= std::abs(d1)) || d1 == 0) return;
    const int s = d1 > 0 ? 1 : -1;
    if (sign != 0 && s != sign) return;
    sign = s;
  }
  vref = 0.5 * (H - 1);
  double lo = 1e300, hi = -1e300;
  for (const auto& c : corners) {
    const double s = pencil_s(c[0], c[1]);
    lo = std::min(lo, s), hi = std::max(hi, s);
  }
  smin = lo;
  const double bins = std::ceil((hi - lo) / ds) + 1;
  if (!(bins < 1 << 16)) return;
  nbins = int(bins);

  // Row sweep: per bin, the rows where the bin's centre line is inside a run.
  struct Emitted {
    int bin;
    float v0, v1;
  };
  std::vector<Emitted> emitted;
  std::vector<float> open(static_cast<std::size_t>(nbins));
  std::vector<std::pair<int, int>> prev, cur;
  const auto first_bin = [&](double s) {  // clamp(ceil((s - smin) / ds - 0.5), 0, nbins)
    const double x = (s - smin) * inv_ds - 0.5;
    if (!(x > 0)) return 0;
    if (x >= nbins) return nbins;
    const int k = int(x);
    return k + int(k < x);
  };
  for (int y = 0; y <= H; ++y) {
    if (prev.empty() && (y == H || mask->row(y).empty())) continue;  // nothing opens or closes
    cur.clear();
    if (y < H) {
      const double c = (vref - y) / (V[1] - V[2] * y);
      const double slope = 1 - V[2] * c, offset = V[0] * c;
      for (const Run& r : mask->row(y)) {
        const int kb = first_bin((r.begin - 0.5) * slope + offset);
        const int ke = first_bin((r.end - 0.5) * slope + offset);
        if (kb < ke) cur.emplace_back(kb, ke);
      }
    }
    const float edge = float(y - 0.5);
    difference(cur, prev,
               [&](int a, int b) { std::fill(open.begin() + a, open.begin() + b, edge); });
    difference(prev, cur, [&](int a, int b) {
      for (int k = a; k < b; ++k) emitted.push_back({k, open[k], edge});
    });
    std::swap(prev, cur);
  }
  bin_start.assign(std::size_t(nbins) + 1, 0);
  for (const Emitted& e : emitted) ++bin_start[e.bin + 1];
  occupied.clear();
  for (int k = 0; k < nbins; ++k) {
    if (bin_start[k + 1] != 0) {
      if (!occupied.empty() && occupied.back().second == k) {
        ++occupied.back().second;
      } else {
        occupied.push_back({k, k + 1});
      }
    }
    bin_start[k + 1] += bin_start[k];
  }
  bin_v.resize(emitted.size() * 2);
  std::vector<uint32_t> fill(bin_start.begin(), bin_start.end() - 1);
  for (const Emitted& e : emitted) {
    const uint32_t at = fill[e.bin]++;
    bin_v[2 * at] = e.v0;
    bin_v[2 * at + 1] = e.v1;
  }
  pencil = true;
}

void PreparedView::Impl::cut_pencil(const Vec3& A, const Vec3& B, std::span<const Interval> in,
                                    std::vector<Range>* keep) const {
  const double lo = in.front().lo, hi = in.back().hi;
  // Whole span in front and inside the image when both end points are (w is linear in t and
  // the image rectangle convex); otherwise clip.
  Range inside{lo, hi};
  const double w0 = A[2] + lo * B[2], w1 = A[2] + hi * B[2];
  bool whole = all_inside;
  if (!whole && w0 > 1e-12 && w1 > 1e-12) {
    const double i0 = 1 / w0, i1 = 1 / w1;
    const double u0 = (A[0] + lo * B[0]) * i0, v0 = (A[1] + lo * B[1]) * i0;
    const double u1 = (A[0] + hi * B[0]) * i1, v1 = (A[1] + hi * B[1]) * i1;
    whole = u0 >= image.u0 && u0 <= image.u1 && v0 >= image.v0 && v0 <= image.v1 &&
            u1 >= image.u0 && u1 <= image.u1 && v1 >= image.v0 && v1 <= image.v1;
  }
  if (!whole) {
    inside = in_rect(A, B, image, lo, hi);
    if (!(inside.lo < inside.hi)) {
      if (keep_outside) keep->push_back({lo, hi});
      return;
    }
    if (keep_outside) keep->push_back({lo, inside.lo});
  }
  // Pencil coordinate of the line from one of its image points x = A + tm B (homogeneous):
  // s = u + d0 (vref - v) / d1 with u = x0/x2, v = x1/x2, d = V - V2 (u, v), in one division.
  const double tm = 0.5 * (inside.lo + inside.hi);
  const double x0 = A[0] + tm * B[0], x1 = A[1] + tm * B[1], x2 = A[2] + tm * B[2];
  const double e0 = V[0] * x2 - V[2] * x0, e1 = V[1] * x2 - V[2] * x1;
  const double s = (x0 * e1 + e0 * (vref * x2 - x1)) / (x2 * e1);
  const double kf = std::floor((s - smin) * inv_ds);
  if (kf >= 0 && kf < nbins) {
    const int k = int(kf);
    const std::size_t from = keep->size();
    for (uint32_t r = bin_start[k]; r < bin_start[k + 1]; ++r) {
      const double y0 = bin_v[2 * r], y1 = bin_v[2 * r + 1];
      double p = inside.lo, q = inside.hi;
      clip_halfline(A[1] - y0 * A[2], B[1] - y0 * B[2], p, q);
      clip_halfline(y1 * A[2] - A[1], y1 * B[2] - B[1], p, q);
      if (p < q) keep->push_back({p, q});
    }
    // v decreasing along t reverses the order.
    if (keep->size() - from > 1 && (*keep)[from].lo > keep->back().lo) {
      std::reverse(keep->begin() + std::ptrdiff_t(from), keep->end());
    }
  }
  if (keep_outside && !whole) keep->push_back({inside.hi, hi});
}

void PreparedView::Impl::cut_walk(const Vec3& A, const Vec3& B, std::span<const Interval> in,
                                  std::vector<Range>* keep) const {
  for (const Interval& iv : in) {
    const Range inside = in_rect(A, B, image, iv.lo, iv.hi);
    if (!(inside.lo < inside.hi)) {
      if (keep_outside) keep->push_back({iv.lo, iv.hi});
      continue;
    }
    if (keep_outside) keep->push_back({iv.lo, inside.lo});
    const std::size_t from = keep->size();
    walk_rows(A, B, inside.lo, inside.hi, *mask, keep);
    sort_merge(keep, from);
    if (keep_outside) keep->push_back({inside.hi, iv.hi});
  }
}

void PreparedView::Impl::cut_walk_distorted(const Vec3& A, const Vec3& B,
                                            std::span<const Interval> in,
                                            std::vector<Range>* keep) const {
  for (const Interval& iv : in) {
    const std::size_t from = keep->size();
    const Range valid = in_rect(A, B, ideal_image, iv.lo, iv.hi);
    if (!(valid.lo < valid.hi)) {
      if (keep_outside) keep->push_back({iv.lo, iv.hi});
      continue;
    }
    if (keep_outside) keep->push_back({iv.lo, valid.lo});
    const auto ideal = [&](double t) -> Eigen::Vector2d {
      const Vec3 h = A + t * B;
      return {h[0] / h[2], h[1] / h[2]};
    };
    const double length = (ideal(valid.hi) - ideal(valid.lo)).norm();
    const int n = std::clamp(int(std::ceil(length / 8.0)), 1, 1024);
    double ta = valid.lo;
    Eigen::Vector2d pa = ideal_to_observed(camera, ideal(ta));
    for (int s = 1; s <= n; ++s) {
      const double tb = s == n ? valid.hi : valid.lo + (valid.hi - valid.lo) * s / n;
      const Eigen::Vector2d pb = ideal_to_observed(camera, ideal(tb));
      // The chord as an affine piece: observed point = pa + (t - ta) g.
      const Eigen::Vector2d g = (pb - pa) / (tb - ta);
      const Vec3 Ap(pa.x() - ta * g.x(), pa.y() - ta * g.y(), 1.0), Bp(g.x(), g.y(), 0.0);
      const Range piece = in_rect(Ap, Bp, image, ta, tb);
      if (piece.lo < piece.hi) {
        if (keep_outside) keep->push_back({ta, piece.lo});
        walk_rows(Ap, Bp, piece.lo, piece.hi, *mask, keep);
        if (keep_outside) keep->push_back({piece.hi, tb});
      } else if (keep_outside) {
        keep->push_back({ta, tb});
      }
      ta = tb;
      pa = pb;
    }
    if (keep_outside) keep->push_back({valid.hi, iv.hi});
    sort_merge(keep, from);
  }
}

PreparedView::PreparedView() : impl_(std::make_unique<Impl>()) {}
PreparedView::PreparedView(PreparedView&&) noexcept = default;
PreparedView& PreparedView::operator=(PreparedView&&) noexcept = default;
PreparedView::~PreparedView() = default;

Expected<PreparedView> PreparedView::create(const Camera& camera, const RunMask& mask,
                                            const Eigen::Vector4d& pencil_point,
                                            const CutOptions& options,
                                            const Eigen::AlignedBox3d* domain) {
  if (mask.width() != camera.width || mask.height() != camera.height) {
    return fail("camera " + camera.id + ": mask is " + std::to_string(mask.width()) + "x" +
                std::to_string(mask.height()) + ", camera is " + std::to_string(camera.width) +
                "x" + std::to_string(camera.height));
  }
  if (camera.width <= 0 || camera.height <= 0) {
    return fail("camera " + camera.id + ": empty image size");
  }
  PreparedView view;
  Impl& m = *view.impl_;
  m.camera = camera;
  m.mask = &mask;
  m.P = camera.projection_matrix();
  m.distorted = !camera.distortion.is_identity();
  const int W = camera.width, H = camera.height;
  m.image = {-0.5, W - 0.5, -0.5, H - 0.5};
  m.seen_rect = m.image;
  if (m.distorted) {
    // Ideal bounding box of the observed image border, padded: beyond it the distortion
    // polynomial is not trusted and the line counts as outside the image.
    const Rect box = detail::ideal_border_box(camera);
    const double pad = 0.02 * std::max(W, H);
    m.seen_rect = box;
    m.ideal_image = {box.u0 - pad, box.u1 + pad, box.v0 - pad, box.v1 + pad};
  } else if (options.allow_pencil) {
    m.build_pencil(pencil_point);
  }
  if (domain != nullptr && !m.distorted) {
    m.all_inside = true;
    for (int k = 0; k < 8; ++k) {
      const Vec3 x = domain->corner(Eigen::AlignedBox3d::CornerType(k));
      const Vec3 h = m.P.leftCols<3>() * x + m.P.col(3);
      m.all_inside = m.all_inside && h[2] > 1e-9 && h[0] / h[2] >= m.image.u0 &&
                     h[0] / h[2] <= m.image.u1 && h[1] / h[2] >= m.image.v0 &&
                     h[1] / h[2] <= m.image.v1;
    }
  }
  return view;
}

bool PreparedView::misses(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double lo,
                          double hi) const {
  const Impl& m = *impl_;
  if (!m.pencil || !m.all_inside) return false;
  // The same arithmetic as cut_line + cut_pencil up to the bin, so the answers agree exactly.
  const double* P = m.P.data();
  const Vec3 A(P[0] * o[0] + P[3] * o[1] + P[6] * o[2] + P[9],
               P[1] * o[0] + P[4] * o[1] + P[7] * o[2] + P[10],
               P[2] * o[0] + P[5] * o[1] + P[8] * o[2] + P[11]);
  const Vec3 B(P[0] * d[0] + P[3] * d[1] + P[6] * d[2], P[1] * d[0] + P[4] * d[1] + P[7] * d[2],
               P[2] * d[0] + P[5] * d[1] + P[8] * d[2]);
  const double tm = 0.5 * (lo + hi);
  const double x0 = A[0] + tm * B[0], x1 = A[1] + tm * B[1], x2 = A[2] + tm * B[2];
  const Vec3& V = m.V;
  const double e0 = V[0] * x2 - V[2] * x0, e1 = V[1] * x2 - V[2] * x1;
  const double s = (x0 * e1 + e0 * (m.vref * x2 - x1)) / (x2 * e1);
  // floor(x) in [0, nbins) <=> x in [0, nbins); truncation is floor for x >= 0.
  const double x = (s - m.smin) * m.inv_ds;
  if (!(x >= 0 && x < m.nbins)) return true;
  const int k = int(x);
  return m.bin_start[k] == m.bin_start[k + 1];
}

bool PreparedView::uses_pencil() const { return impl_->pencil; }

std::pair<double, double> PreparedView::seen(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                             double lo, double hi) const {
  const Impl& m = *impl_;
  const Vec3 A = m.P.leftCols<3>() * o + m.P.col(3), B = m.P.leftCols<3>() * d;
  const Range r = in_rect(A, B, m.seen_rect, lo, hi);
  return {r.lo, r.hi};
}
bool PreparedView::domain_inside_image() const { return impl_->all_inside; }

void PreparedView::cut_line(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                            std::span<const Interval> in, std::vector<Interval>* out,
                            CutScratch* scratch) const {
  if (in.empty()) return;
  std::vector<Range>& keep = scratch->keep;
  std::vector<Range>& result = scratch->result;
  keep.clear();
  const Impl& m = *impl_;
  const double* P = m.P.data();  // column-major 3x4
  const Vec3 A(P[0] * o[0] + P[3] * o[1] + P[6] * o[2] + P[9],
               P[1] * o[0] + P[4] * o[1] + P[7] * o[2] + P[10],
               P[2] * o[0] + P[5] * o[1] + P[8] * o[2] + P[11]);
  const Vec3 B(P[0] * d[0] + P[3] * d[1] + P[6] * d[2], P[1] * d[0] + P[4] * d[1] + P[7] * d[2],
               P[2] * d[0] + P[5] * d[1] + P[8] * d[2]);
  if (m.pencil) {
    m.cut_pencil(A, B, in, &keep);
    if (keep.empty()) return;
  } else if (m.distorted) {
    m.cut_walk_distorted(A, B, in, &keep);
  } else {
    m.cut_walk(A, B, in, &keep);
  }
  // out = in ∩ keep (keep is sorted; touching pieces are merged by emit()).
  result.clear();
  std::size_t p = 0;
  for (const Interval& iv : in) {
    while (p < keep.size() && keep[p].hi <= iv.lo) ++p;
    for (std::size_t q = p; q < keep.size() && keep[q].lo < iv.hi; ++q) {
      const double lo = std::max<double>(iv.lo, keep[q].lo),
                   hi = std::min<double>(iv.hi, keep[q].hi);
      if (lo < hi) result.push_back({lo, hi});
    }
  }
  emit(result, out, out->size());
}

bool GridCutAccess::make(const PreparedView& view, const GridSpec& g, Fast* f) {
  using Fast = GridCutAccess::Fast;
  const PreparedView::Impl& m = *view.impl_;
  // Any view with pencil bins: on the part of a column in front of the camera the image row is a
  // monotone function of t whose range holds every image row (the pencil condition puts the
  // vanishing point's row outside the image), so a run end row maps to one front t; the seen
  // range (in front, in the image) clips the rest.
  if (!m.pencil) return false;
  f->whole = m.all_inside;
  const Vec3& V = m.V;
  Vec3 o = Vec3::Zero();
  o[g.u()] = g.box_min[g.u()] + 0.5 * g.du();
  o[g.v()] = g.box_min[g.v()] + 0.5 * g.dv();
  const Vec3 A0 = m.P.leftCols<3>() * o + m.P.col(3);
  const Vec3 Ai = m.P.col(g.u()) * g.du(), Aj = m.P.col(g.v()) * g.dv();
  // Image line L = A x V crosses row vref at s = -(L1 vref + L2) / L0; bin coordinate
  // (s - smin) / ds = N(A) / D(A), both linear in A.
  const Vec3 cn =
      Vec3(m.vref * V[2] - V[1], V[0] - m.smin * V[2], m.smin * V[1] - m.vref * V[0]) * m.inv_ds;
  const Vec3 cd(0, V[2], -V[1]);
  f->n0 = cn.dot(A0), f->ni = cn.dot(Ai), f->nj = cn.dot(Aj);
  f->d0 = cd.dot(A0), f->di = cd.dot(Ai), f->dj = cd.dot(Aj);
  f->a10 = A0[1], f->a1i = Ai[1], f->a1j = Aj[1];
  f->a20 = A0[2], f->a2i = Ai[2], f->a2j = Aj[2];
  f->image = {A0, Ai, Aj, V, {m.image.u0, m.image.u1, m.image.v0, m.image.v1}};
  f->nbins = m.nbins;
  f->bin_start = m.bin_start.data();
  f->occupied = &m.occupied;
  f->occupied_before.resize(std::size_t(m.nbins) + 1);
  f->occupied_before[0] = 0;
  for (int k = 0; k < m.nbins; ++k)
    f->occupied_before[k + 1] = f->occupied_before[k] + (m.bin_start[k + 1] > m.bin_start[k]);
  f->v1 = V[1], f->v2 = V[2];
  f->row_lo.assign(std::size_t(m.nbins), 1e30f);
  f->row_hi.assign(std::size_t(m.nbins), -1e30f);
  for (int k = 0; k < m.nbins; ++k)
    for (uint32_t r = m.bin_start[k]; r < m.bin_start[k + 1]; ++r) {
      f->row_lo[k] = std::min(f->row_lo[k], m.bin_v[2 * r]);
      f->row_hi[k] = std::max(f->row_hi[k], m.bin_v[2 * r + 1]);
    }
  const int groups = (m.nbins + Fast::kGroup - 1) / Fast::kGroup;
  f->group_lo.assign(std::size_t(groups), 1e30f);
  f->group_hi.assign(std::size_t(groups), -1e30f);
  for (int k = 0; k < m.nbins; ++k) {
    f->group_lo[k / Fast::kGroup] = std::min(f->group_lo[k / Fast::kGroup], f->row_lo[k]);
    f->group_hi[k / Fast::kGroup] = std::max(f->group_hi[k / Fast::kGroup], f->row_hi[k]);
  }
  // Run ends are pixel-row edges y - 0.5 (build_pencil): one division per row edge, not per end.
  const int H = m.mask->height();
  std::vector<double> inv(std::size_t(H) + 1);
  for (int y = 0; y <= H; ++y) inv[std::size_t(y)] = 1 / (V[1] - (y - 0.5) * V[2]);
  f->ends.resize(m.bin_v.size());
  for (std::size_t r = 0; r < m.bin_v.size(); ++r) {
    const double y = m.bin_v[r], a = inv[std::size_t(std::lround(y + 0.5))];
    f->ends[r] = {y * a, a};
  }
  return true;
}

}  // namespace studio::hull
