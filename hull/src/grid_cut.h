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

#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

struct GridCutAccess {
  struct End {
    double p, q;  // t = p A2 - q A1
  };
  using Span = std::pair<int, int>;
  struct Fast {
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
  // domain does not project inside its image.
  // A fast cutter for `view` over grid g, or false when the view has no pencil bins or the
  // domain does not project inside its image (defined in silhouette_cut.cc, beside the bins).
  static bool make(const PreparedView& view, const GridSpec& g, Fast* f);
};

}  // namespace studio::hull
