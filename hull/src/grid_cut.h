#pragma once
// The grid fast path of cut() (private to studio_hull; silhouette_cut.cc builds it from a
// PreparedView, grid_cut.cc runs it).
//
// The grid fast path of cut(): for a view whose pencil bins are built and whose whole domain
// projects inside the image, every column (i, j) of the grid is the line o(i, j) + t e_axis with
// o affine in (i, j), so its homogeneous image A(i, j) = P (o, 1) is affine in (i, j) and its
// direction's image is the vanishing point V itself. The column's pencil coordinate (where its
// image line A x V crosses the reference row) is then a ratio of two affine functions of (i, j)
// — one division per column and camera — and a bin run [y0, y1) maps back to the column by
// t(y) = (y A2 - A1) / (V1 - y V2) = y a(y) A2 - a(y) A1 with a(y) = 1 / (V1 - y V2) precomputed
// per run end, so cutting costs a few multiplications per run and no division. Along a grid row
// the bin coordinate is a monotone Moebius function of i, so the columns whose bins hold
// silhouette form a few i-ranges per row, found by inverting it at the ends of the runs of
// occupied bins: whole stretches of empty columns are skipped without touching them.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "frustum.h"
#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

// The homogeneous image of the grid's columns in one camera: column (i, j) at parameter t images
// to A(i, j) + t B with A affine in (i, j) and B = P (e_axis, 0) constant. Every "seen" test
// (detail::in_rect) is then a half-space in (i, j, t), so the seen set is convex in (i, j, t):
// bounds over a block of columns follow from its four corner columns.
struct ColumnImage {
  Eigen::Vector3d a0, ai, aj, b;
  detail::Rect rect;

  Eigen::Vector3d A(double i, double j) const { return a0 + i * ai + j * aj; }
  detail::Range seen(double i, double j, double lo, double hi) const {
    return detail::in_rect(A(i, j), b, rect, lo, hi);
  }
  // For the block of columns [i0, i1] x [j0, j1] (corner columns included):
  // inner: the t-range seen from EVERY column of the block (the corners' common range: the
  //        block's cross-section at such t is the convex hull of four seen points);
  // outer: a t-range holding everything any column of the block sees (per half-space, the
  //        loosest corner bound; their intersection).
  detail::Range block_inner(double i0, double i1, double j0, double j1, double lo, double hi) const;
  detail::Range block_outer(double i0, double i1, double j0, double j1, double lo, double hi) const;
};

struct GridCutAccess {
  struct End {
    double p, q;  // t = p A2 - q A1
  };
  using Span = std::pair<int, int>;
  struct Fast {
    bool whole = true;  // the domain projects inside the image (else `image` clips each column)
    ColumnImage image;
    std::vector<uint32_t> occupied_before;  // occupied_before[k]: bins < k holding silhouette
    double n0, ni, nj, d0, di, dj;  // bin coordinate = (n0 + j nj + i ni) / (d0 + j dj + i di)
    double a10, a1i, a1j, a20, a2i, a2j;  // A1, A2 of column (i, j)
    int nbins = 0;
    const uint32_t* bin_start = nullptr;
    const std::vector<Span>* occupied = nullptr;  // maximal runs of bins holding silhouette
    std::vector<End> ends;                        // two per bin run, in bin order

    // The column's bin when it holds silhouette, else -1.
    int bin(int i, int j) const {
      const double x = (n0 + j * nj + i * ni) / (d0 + j * dj + i * di);
      if (!(x >= 0 && x < nbins)) return -1;
      const int k = int(x);
      return bin_start[k] == bin_start[k + 1] ? -1 : k;
    }
    // Bins [*k0, *k1) holding every column of the block [i0, i1] x [j0, j1] (corners included):
    // the bin coordinate is a ratio of affine functions, monotone along each axis where its
    // denominator keeps its sign, so its extremes are at the corners (one bin of margin for
    // rounding). False when the denominator changes sign over the block (no bound).
    bool block_bins(int i0, int i1, int j0, int j1, int* k0, int* k1) const {
      double lo = 1e300, hi = -1e300;
      int sign = 0;
      for (const int i : {i0, i1})
        for (const int j : {j0, j1}) {
          const double D = d0 + j * dj + i * di;
          const int s = D > 0 ? 1 : D < 0 ? -1 : 0;
          if (s == 0 || (sign != 0 && s != sign)) return false;
          sign = s;
          const double x = (n0 + j * nj + i * ni) / D;
          lo = std::min(lo, x), hi = std::max(hi, x);
        }
      if (!(std::isfinite(lo) && std::isfinite(hi))) return false;
      *k0 = std::clamp(int(std::floor(std::max(lo, -2.0))) - 1, 0, nbins);
      *k1 = std::clamp(int(std::floor(std::min(hi, nbins + 2.0))) + 2, 0, nbins);
      return true;
    }
    // Whether no column of the block can have a bin holding silhouette.
    bool block_empty(int i0, int i1, int j0, int j1) const {
      int k0 = 0, k1 = 0;
      return block_bins(i0, i1, j0, j1, &k0, &k1) && occupied_before[k1] == occupied_before[k0];
    }
    // The image rows [*lo, *hi] spanned by the runs of bins [k0, k1) (*lo > *hi: none).
    static constexpr int kGroup = 32;
    std::vector<float> row_lo, row_hi;      // per bin
    std::vector<float> group_lo, group_hi;  // per kGroup bins
    void rows(int k0, int k1, double* lo, double* hi) const {
      float a = 1e30f, b = -1e30f;
      int k = k0;
      for (; k < k1 && k % kGroup != 0; ++k) a = std::min(a, row_lo[k]), b = std::max(b, row_hi[k]);
      for (; k + kGroup <= k1; k += kGroup)
        a = std::min(a, group_lo[k / kGroup]), b = std::max(b, group_hi[k / kGroup]);
      for (; k < k1; ++k) a = std::min(a, row_lo[k]), b = std::max(b, row_hi[k]);
      *lo = a, *hi = b;
    }
    double v1 = 0, v2 = 0;  // V[1], V[2]: column (i, j) meets image row y at
                            // t = (y A2 - A1) / (v1 - y v2), affine in (i, j) for a fixed y
    // A t-range holding every t where a column of the block [i0, i1] x [j0, j1] images into the
    // rows [y0, y1]: t(y) is monotone in y along a column and affine in (i, j) for a fixed y.
    CutScratch::Piece block_t(int i0, int i1, int j0, int j1, double y0, double y1) const {
      double lo = 1e300, hi = -1e300;
      for (const double y : {y0, y1}) {
        const double a = 1 / (v1 - y * v2);
        for (const int i : {i0, i1})
          for (const int j : {j0, j1}) {
            const double A1 = a10 + j * a1j + i * a1i, A2 = a20 + j * a2j + i * a2i;
            const double t = (y * A2 - A1) * a;
            lo = std::min(lo, t), hi = std::max(hi, t);
          }
      }
      return {lo, hi};
    }
    // Sorted, disjoint i-ranges of row j holding every column whose bin holds silhouette (a
    // superset: one column of margin for rounding; bin() decides exactly).
    void row_spans(int j, int nu, std::vector<Span>* r) const {
      r->clear();
      const double N = n0 + j * nj, D = d0 + j * dj;
      const double pole = -D / di;  // x(i) has its pole here (outside the domain)
      for (const auto& [ka, kb] : *occupied) {
        const double ia = (ka * D - N) / (ni - ka * di), ib = (kb * D - N) / (ni - kb * di);
        const double lo = std::min(ia, ib), hi = std::max(ia, ib);
        if (!(std::isfinite(lo) && std::isfinite(hi)) || (pole >= lo && pole <= hi)) {
          r->assign(1, {0, nu});  // degenerate: keep the whole row
          return;
        }
        const int a = int(std::floor(std::clamp(lo, -4.0, nu + 4.0))) - 1;
        const int b = int(std::ceil(std::clamp(hi, -4.0, nu + 4.0))) + 2;
        if (std::max(a, 0) < std::min(b, nu)) r->push_back({std::max(a, 0), std::min(b, nu)});
      }
      if (r->size() > 1) {
        std::sort(r->begin(), r->end());
        std::size_t w = 0;
        for (std::size_t k = 1; k < r->size(); ++k) {
          if ((*r)[k].first <= (*r)[w].second) {
            (*r)[w].second = std::max((*r)[w].second, (*r)[k].second);
          } else {
            (*r)[++w] = (*r)[k];
          }
        }
        r->resize(w + 1);
      }
    }
    // The t-ranges of bin k's runs on column (i, j), ascending.
    void pieces(int i, int j, int k, std::vector<CutScratch::Piece>* pieces) const {
      const double A1 = a10 + j * a1j + i * a1i, A2 = a20 + j * a2j + i * a2i;
      const uint32_t r0 = bin_start[k], r1 = bin_start[k + 1];
      const End* e = ends.data() + 2 * r0;
      const std::size_t n = r1 - r0;
      pieces->resize(n);
      CutScratch::Piece* pc = pieces->data();
      if ((d0 + j * dj + i * di) > 0) {
        for (std::size_t r = 0; r < n; ++r)
          pc[n - 1 - r] = {e[2 * r + 1].p * A2 - e[2 * r + 1].q * A1,
                           e[2 * r].p * A2 - e[2 * r].q * A1};
      } else {
        for (std::size_t r = 0; r < n; ++r)
          pc[r] = {e[2 * r].p * A2 - e[2 * r].q * A1, e[2 * r + 1].p * A2 - e[2 * r + 1].q * A1};
      }
    }
    // out = in ∩ (the t-ranges of bin k's runs), float end points, touching pieces merged.
    void cut(int i, int j, int k, std::span<const Interval> in,
             std::vector<CutScratch::Piece>* pieces, std::vector<Interval>* out) const {
      const double A1 = a10 + j * a1j + i * a1i, A2 = a20 + j * a2j + i * a2i;
      const uint32_t r0 = bin_start[k], r1 = bin_start[k + 1];
      const End* e = ends.data() + 2 * r0;
      const std::size_t n = r1 - r0;
      pieces->resize(n);
      CutScratch::Piece* pc = pieces->data();
      // t decreases with the image row when D > 0: the runs come in reverse t order.
      if ((d0 + j * dj + i * di) > 0) {
        for (std::size_t r = 0; r < n; ++r)
          pc[n - 1 - r] = {e[2 * r + 1].p * A2 - e[2 * r + 1].q * A1,
                           e[2 * r].p * A2 - e[2 * r].q * A1};
      } else {
        for (std::size_t r = 0; r < n; ++r)
          pc[r] = {e[2 * r].p * A2 - e[2 * r].q * A1, e[2 * r + 1].p * A2 - e[2 * r + 1].q * A1};
      }
      std::size_t p = 0;
      for (const Interval& iv : in) {
        const double ilo = iv.lo, ihi = iv.hi;
        while (p < n && pc[p].hi <= ilo) ++p;
        for (std::size_t q = p; q < n && pc[q].lo < ihi; ++q) {
          const float flo = float(std::max(ilo, pc[q].lo)), fhi = float(std::min(ihi, pc[q].hi));
          if (!(fhi > flo)) continue;
          if (!out->empty() && out->back().hi >= flo) {
            out->back().hi = std::max(out->back().hi, fhi);
          } else {
            out->push_back({flo, fhi});
          }
        }
      }
    }
  };

  // A fast cutter for `view` over grid g, or false when the view has no pencil bins or the
  // domain is not wholly in front of the camera (defined in silhouette_cut.cc, beside the
  // bins). f->whole tells whether the domain also projects inside the image.
  static bool make(const PreparedView& view, const GridSpec& g, Fast* f);
};

// The column image of a camera over grid g (first column centre at i = j = 0).
ColumnImage column_image(const Camera& camera, const GridSpec& g);

// The cut on a general rig (grid_blocks.cc): some views see only part of the domain, or have no
// pencil bins, or the policy needs coverage. Coarse-to-fine over blocks of columns: a block
// carries a conservative t-set (a superset of every one of its columns' hull) shrunk by
//  - a fully-seeing fast view whose bins over the block hold no silhouette (the block dies),
//  - a partially-seeing fast view whose bins hold no silhouette: the block keeps only what that
//    view does not see from every column (the complement of the inner seen range),
//  - coverage: t seen by fewer than `need` views even by the outer seen ranges is cut;
// blocks whose set empties are skipped whole, the rest split in four down to small leaves whose
// columns are cut exactly (the same arithmetic as PreparedView::cut_line: exact crossings kept
// for every interval that survives). Writes the columns' intervals into out/counts like
// cut_grid's workers (counts[c + 1] = intervals of column c).
struct BlockCutViews {
  std::vector<const GridCutAccess::Fast*> full;     // see the whole domain
  std::vector<const GridCutAccess::Fast*> partial;  // pencil bins, see part of the domain
  std::vector<const PreparedView*> general;         // cut line by line
  std::vector<ColumnImage> general_image;           // their column images (coverage)
  int need = 0;                                     // views that must see a point
};
void cut_blocks(const GridSpec& g, const SegmentSet* src, const BlockCutViews& views, int j0,
                int j1, std::vector<Interval>* out, std::vector<uint32_t>* counts);

}  // namespace studio::hull
