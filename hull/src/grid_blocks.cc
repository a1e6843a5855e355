// The cut on a general rig (grid_cut.h, cut_blocks): coarse-to-fine over tiles of columns with
// conservative t-sets, exact per-column cuts in the tiles that survive.
#include <algorithm>
#include <cmath>
#include <vector>

#include "frustum.h"
#include "grid_cut.h"

namespace studio::hull {
namespace {

using detail::Range;
using Vec3 = Eigen::Vector3d;

constexpr int kTile = 4;  // leaf tiles of kTile x kTile columns

// set ∩= cover (both sorted, disjoint).
void intersect_ranges(std::vector<Range>* set, const std::vector<Range>& cover,
                      std::vector<Range>* tmp) {
  tmp->clear();
  std::size_t p = 0;
  for (const Range& r : *set) {
    while (p < cover.size() && cover[p].hi <= r.lo) ++p;
    for (std::size_t q = p; q < cover.size() && cover[q].lo < r.hi; ++q) {
      const double a = std::max(r.lo, cover[q].lo), b = std::min(r.hi, cover[q].hi);
      if (a < b) tmp->push_back({a, b});
    }
  }
  std::swap(*set, *tmp);
}

struct Work {
  std::vector<Range> tmp, cover, ranges, keep, pieces;
  std::vector<std::pair<double, int>> events;
  std::vector<Interval> a, b;
  CutScratch scratch;
};

}  // namespace

Range ColumnImage::block_inner(double i0, double i1, double j0, double j1, double lo,
                               double hi) const {
  for (const double i : {i0, i1})
    for (const double j : {j0, j1}) {
      const Range r = seen(i, j, lo, hi);
      lo = std::max(lo, r.lo), hi = std::min(hi, r.hi);
    }
  return {lo, hi};
}

Range ColumnImage::block_outer(double i0, double i1, double j0, double j1, double lo,
                               double hi) const {
  // Per half-space alpha(i, j) + t beta >= 0 (alpha affine), the loosest corner bound.
  const Vec3 c[4] = {A(i0, j0), A(i1, j0), A(i0, j1), A(i1, j1)};
  double o_lo = lo, o_hi = hi;
  const auto half = [&](const Vec3& w, double beta) {  // alpha = w . A
    double a_max = -1e300;  // the loosest bound comes from the largest alpha either way
    for (const Vec3& a : c) a_max = std::max(a_max, w.dot(a));
    if (beta > 0) {
      o_lo = std::max(o_lo, -a_max / beta);
    } else if (beta < 0) {
      o_hi = std::min(o_hi, -a_max / beta);
    } else if (a_max < 0) {
      o_lo = 1, o_hi = 0;
    }
  };
  const detail::Rect& r = rect;
  half(Vec3(0, 0, 1), b[2]);  // w > 0 (the 1e-12 of in_rect only makes the outer bound looser)
  half(Vec3(1, 0, -r.u0), b[0] - r.u0 * b[2]);
  half(Vec3(-1, 0, r.u1), r.u1 * b[2] - b[0]);
  half(Vec3(0, 1, -r.v0), b[1] - r.v0 * b[2]);
  half(Vec3(0, -1, r.v1), r.v1 * b[2] - b[1]);
  return {o_lo, o_hi};
}

ColumnImage column_image(const Camera& camera, const GridSpec& g) {
  const detail::Frustum f = detail::Frustum::of(camera);
  Vec3 o = Vec3::Zero();
  o[g.u()] = g.box_min[g.u()] + 0.5 * g.du();
  o[g.v()] = g.box_min[g.v()] + 0.5 * g.dv();
  ColumnImage c;
  c.a0 = f.P.leftCols<3>() * o + f.P.col(3);
  c.ai = f.P.col(g.u()) * g.du();
  c.aj = f.P.col(g.v()) * g.dv();
  c.b = f.P.col(g.a());
  c.rect = f.rect;
  return c;
}

// A set of sorted pieces lies within [lo, hi].
bool within(const std::vector<Range>& set, const Range& r) {
  return set.empty() || (r.lo <= set.front().lo && set.back().hi <= r.hi);
}
// A set of sorted pieces lies within the sorted pieces `cover`.
bool within(const std::vector<Range>& set, const std::vector<Range>& cover) {
  std::size_t q = 0;
  for (const Range& r : set) {
    while (q < cover.size() && cover[q].hi <= r.lo) ++q;
    if (q == cover.size() || !(cover[q].lo <= r.lo && r.hi <= cover[q].hi)) return false;
  }
  return true;
}

void cut_blocks(const GridSpec& g, const SegmentSet* src, const BlockCutViews& views, int j0,
                int j1, std::vector<Interval>* out, std::vector<uint32_t>* counts) {
  const int nu = g.cells_u;
  const double t0 = g.t_min(), t1 = g.t_max();
  const int need = views.need - int(views.full.size());  // the full views see everything
  const int tiles_u = (nu + kTile - 1) / kTile, tiles_v = (j1 - j0 + kTile - 1) / kTile;
  if (tiles_v <= 0) return;
  const std::size_t P = views.partial.size(), G = views.general_image.size();
  // Per surviving leaf tile: its set; whether per-column coverage can be skipped (every point
  // of the set is seen by `need` views from every column) and, per partial view, whether that
  // view sees the whole set from every column (its per-column seen range need not be computed).
  struct Tile {
    bool alive = false, covered = false;
    std::vector<Range> set;
    std::vector<char> sees;
  };
  std::vector<Tile> tiles(std::size_t(tiles_u) * tiles_v);
  Work w;
  std::vector<Range> ranges_all, inner(P + G), outer(P + G), inner_cover;

  // Coarse to fine over tile ranges [tu0, tu1) x [tv0, tv1) with the parent's set.
  struct Block {
    int tu0, tu1, tv0, tv1;
    std::vector<Range> set;
  };
  std::vector<Block> stack;
  stack.push_back({0, tiles_u, 0, tiles_v, {{t0, t1}}});
  while (!stack.empty()) {
    Block blk = std::move(stack.back());
    stack.pop_back();
    const int i0 = blk.tu0 * kTile, i1 = std::min(blk.tu1 * kTile, nu) - 1;
    const int bj0 = j0 + blk.tv0 * kTile, bj1 = std::min(j0 + blk.tv1 * kTile, j1) - 1;
    std::vector<Range>& set = blk.set;
    bool dead = false;
    for (const auto* f : views.full) {
      if (f->block_empty(i0, i1, bj0, bj1)) {
        dead = true;
        break;
      }
    }
    if (dead) continue;
    // A partial view keeps, of what it sees from every column of the block (the inner seen
    // range), only the t where some column of the block can image into its silhouette's rows.
    std::size_t done = 0;
    for (; done < P && !set.empty(); ++done) {
      const auto* f = views.partial[done];
      inner[done] = f->image.block_inner(i0, i1, bj0, bj1, t0, t1);
      int k0 = 0, k1 = 0;
      if (!(inner[done].lo < inner[done].hi) || !f->block_bins(i0, i1, bj0, bj1, &k0, &k1))
        continue;
      double y0 = 0, y1 = 0;
      f->rows(k0, k1, &y0, &y1);
      w.keep.clear();
      w.keep.push_back({t0 - 1, inner[done].lo});
      if (y0 <= y1) {
        const Range sil = f->block_t(i0, i1, bj0, bj1, y0, y1);
        const double a = std::max(sil.lo, inner[done].lo), b = std::min(sil.hi, inner[done].hi);
        if (a < b) w.keep.push_back({a, b});
      }
      w.keep.push_back({inner[done].hi, t1 + 1});
      intersect_ranges(&set, w.keep, &w.tmp);
    }
    if (set.empty()) continue;
    // Coverage: t seen by fewer than `need` views even by the outer ranges.
    if (need > 0) {
      for (std::size_t k = 0; k < P; ++k)
        outer[k] = views.partial[k]->image.block_outer(i0, i1, bj0, bj1, t0, t1);
      for (std::size_t k = 0; k < G; ++k)
        outer[P + k] = views.general_image[k].block_outer(i0, i1, bj0, bj1, t0, t1);
      w.cover.clear();
      detail::at_least(outer, need, t0, t1, &w.events, &w.cover);
      intersect_ranges(&set, w.cover, &w.tmp);
    }
    if (set.empty()) continue;
    const int su = blk.tu1 - blk.tu0, sv = blk.tv1 - blk.tv0;
    if (su == 1 && sv == 1) {
      Tile& tile = tiles[std::size_t(blk.tu0) + std::size_t(blk.tv0) * tiles_u];
      tile.alive = true;
      tile.sees.resize(P);
      for (std::size_t k = 0; k < P; ++k) tile.sees[k] = within(set, inner[k]);
      for (std::size_t k = 0; k < G; ++k)
        inner[P + k] = views.general_image[k].block_inner(i0, i1, bj0, bj1, t0, t1);
      inner_cover.clear();
      detail::at_least(inner, need, t0, t1, &w.events, &inner_cover);
      tile.covered = need <= 0 || within(set, inner_cover);
      tile.set = std::move(set);
      continue;
    }
    const int mu = blk.tu0 + (su + 1) / 2, mv = blk.tv0 + (sv + 1) / 2;
    for (const auto& [a, b] : {std::pair{blk.tu0, mu}, std::pair{mu, blk.tu1}})
      for (const auto& [c, d] : {std::pair{blk.tv0, mv}, std::pair{mv, blk.tv1}})
        if (a < b && c < d) stack.push_back({a, b, c, d, set});
  }

  // Exact cut of the columns of the surviving tiles, in column order.
  const Interval full_column{float(t0), float(t1)};
  std::vector<Range> seen(P);
  std::vector<int> bins(P);
  Vec3 d = Vec3::Zero();
  d[g.a()] = 1;
  for (int j = j0; j < j1; ++j) {
    const int tv = (j - j0) / kTile;
    for (int tu = 0; tu < tiles_u; ++tu) {
      const Tile& tile = tiles[std::size_t(tu) + std::size_t(tv) * tiles_u];
      if (!tile.alive) continue;
      for (int i = tu * kTile; i < std::min(nu, (tu + 1) * kTile); ++i) {
        const std::size_t c = std::size_t(i) + std::size_t(j) * std::size_t(nu);
        const std::span<const Interval> col =
            src ? src->column(c) : std::span<const Interval>(&full_column, 1);
        if (col.empty()) continue;
        w.a.clear();
        detail::intersect(col, tile.set, &w.a);
        bool dead = w.a.empty();
        for (const auto* f : views.full) {
          if (dead) break;
          const int k = f->bin(i, j);
          if (k < 0) {
            dead = true;
            break;
          }
          w.b.clear();
          f->cut(i, j, k, w.a, &w.pieces, &w.b);
          std::swap(w.a, w.b);
          dead = w.a.empty();
        }
        // First the cheapest test that can kill the column: a view that sees all of it and
        // whose bin holds no silhouette.
        for (std::size_t p = 0; p < P && !dead; ++p) {
          bins[p] = views.partial[p]->bin(i, j);
          dead = tile.sees[p] && bins[p] < 0;
        }
        for (std::size_t p = 0; p < P && !dead; ++p) {
          const auto* f = views.partial[p];
          const int k = bins[p];
          if (tile.sees[p]) {  // the column's set lies in what this view sees: bins decide
            w.b.clear();
            f->cut(i, j, k, w.a, &w.pieces, &w.b);
            std::swap(w.a, w.b);
            dead = w.a.empty();
            continue;
          }
          seen[p] = f->image.seen(i, j, t0, t1);
          if (!(seen[p].lo < seen[p].hi)) continue;
          w.keep.clear();
          w.keep.push_back({t0 - 1, seen[p].lo});
          if (k >= 0) {
            f->pieces(i, j, k, &w.pieces);
            for (const Range& r : w.pieces) {
              const double a = std::max(r.lo, seen[p].lo), b = std::min(r.hi, seen[p].hi);
              if (a < b) w.keep.push_back({a, b});
            }
          }
          w.keep.push_back({seen[p].hi, t1 + 1});
          w.b.clear();
          detail::intersect(w.a, w.keep, &w.b);
          std::swap(w.a, w.b);
          dead = w.a.empty();
        }
        if (!dead && !tile.covered) {
          ranges_all.clear();
          for (std::size_t p = 0; p < P; ++p)
            ranges_all.push_back(tile.sees[p] ? Range{t0, t1} : seen[p]);
          for (const ColumnImage& ci : views.general_image)
            ranges_all.push_back(ci.seen(i, j, t0, t1));
          w.cover.clear();
          detail::at_least(ranges_all, need, t0, t1, &w.events, &w.cover);
          w.b.clear();
          detail::intersect(w.a, w.cover, &w.b);
          std::swap(w.a, w.b);
          dead = w.a.empty();
        }
        if (!dead && !views.general.empty()) {
          Vec3 o;
          o[g.u()] = g.box_min[g.u()] + (i + 0.5) * g.du();
          o[g.v()] = g.box_min[g.v()] + (j + 0.5) * g.dv();
          o[g.a()] = 0;
          for (const PreparedView* view : views.general) {
            w.b.clear();
            view->cut_line(o, d, w.a, &w.b, &w.scratch);
            std::swap(w.a, w.b);
            if (w.a.empty()) break;
          }
        }
        if (dead) continue;
        out->insert(out->end(), w.a.begin(), w.a.end());
        (*counts)[c + 1] = uint32_t(w.a.size());
      }
    }
  }
}

}  // namespace studio::hull
