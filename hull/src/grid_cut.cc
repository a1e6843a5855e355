// The silhouette cut of a whole segment set (cut(), visual_hull()): the grid fast path of
// grid_cut.h for views whose pencil bins cover the domain, PreparedView::cut_line for the rest;
// columns are independent and split over threads by grid rows.
#include "grid_cut.h"

#include <algorithm>
#include <thread>
#include <vector>

#include "hull/silhouette_cut.h"

namespace studio::hull {
namespace {

using Vec3 = Eigen::Vector3d;
using Range = CutScratch::Piece;

}  // namespace

namespace {

// Cuts the columns of `src` (nullptr: every column full) by every view into `dst`.
Expected<void> cut_grid(const GridSpec& g, const SegmentSet* src, std::span<const View> views,
                        const CutOptions& options, SegmentSet* dst) {
  if (auto ok = options.validate(); !ok) return ok;
  Eigen::Vector4d X = Eigen::Vector4d::Zero();
  X[g.a()] = 1;  // the columns meet at infinity along the continuous axis
  std::vector<PreparedView> prepared;
  prepared.reserve(views.size());
  const Eigen::AlignedBox3d domain(g.box_min, g.box_max);
  for (const View& v : views) {
    auto p = PreparedView::create(*v.camera, *v.mask, X, options, &domain);
    if (!p) return std::unexpected(p.error());
    prepared.push_back(std::move(*p));
  }
  // Views with pencil bins over the whole domain take the grid fast path; the rest cut line by
  // line. Cutting is an intersection, so the order of the views does not matter up to where
  // touching float pieces merge; it is fixed, so the result does not depend on the threads.
  std::vector<GridCutAccess::Fast> fast;
  std::vector<const PreparedView*> general;
  std::vector<const Camera*> general_camera;
  for (std::size_t k = 0; k < prepared.size(); ++k) {
    GridCutAccess::Fast f;
    if (GridCutAccess::make(prepared[k], g, &f)) {
      fast.push_back(std::move(f));
    } else {
      general.push_back(&prepared[k]);
      general_camera.push_back(views[k].camera);
    }
  }
  const int need = options.required_views(views.size());
  // The studio case: every view sees the whole domain with pencil bins (the policy holds for
  // every point once enough of them do). Otherwise the coarse-to-fine cut of grid_blocks.cc.
  const bool studio = general.empty() && need <= int(fast.size()) &&
                      std::all_of(fast.begin(), fast.end(), [](const auto& f) { return f.whole; });
  BlockCutViews block_views;
  if (!studio) {
    for (const auto& f : fast) (f.whole ? block_views.full : block_views.partial).push_back(&f);
    block_views.general = general;
    for (const Camera* c : general_camera) block_views.general_image.push_back(column_image(*c, g));
    block_views.need = need;
  }
  Vec3 d = Vec3::Zero();
  d[g.a()] = 1;
  const int nu = g.cells_u, nv = g.cells_v;
  const std::size_t columns = g.columns();
  const Interval full_column{float(g.t_min()), float(g.t_max())};
  const int T = int(
      std::min<std::size_t>(std::size_t(options.threads), std::max<std::size_t>(columns / 256, 1)));
  std::vector<std::vector<Interval>> chunk_iv(T);
  std::vector<uint32_t> start(columns + 1, 0);  // counts at c + 1 first, prefix sums at the end
  const auto work = [&](int chunk) {
    const int j0 = int(int64_t(nv) * chunk / T), j1 = int(int64_t(nv) * (chunk + 1) / T);
    std::vector<Interval>& out = chunk_iv[chunk];
    if (!studio) return cut_blocks(g, src, block_views, j0, j1, &out, &start);
    std::vector<Interval> a, b;
    std::vector<Range> pieces;
    std::vector<GridCutAccess::Span> alive, spans, next;
    CutScratch scratch;
    const double du = g.du(), dv = g.dv();
    const std::size_t F = fast.size();
    std::vector<int> bins(F);
    for (int j = j0; j < j1; ++j) {
      // Candidate columns of the row: the intersection of every fast view's row spans.
      alive.assign(1, {0, nu});
      for (std::size_t f = 0; f < F && !alive.empty(); ++f) {
        fast[f].row_spans(j, nu, &spans);
        next.clear();
        std::size_t q = 0;
        for (const auto& [x0, x1] : alive) {
          while (q < spans.size() && spans[q].second <= x0) ++q;
          for (std::size_t r = q; r < spans.size() && spans[r].first < x1; ++r) {
            const int lo = std::max(x0, spans[r].first), hi = std::min(x1, spans[r].second);
            if (lo < hi) next.push_back({lo, hi});
          }
        }
        std::swap(alive, next);
      }
      for (const auto& [x0, x1] : alive) {
        for (int i = x0; i < x1; ++i) {
          const std::size_t c = std::size_t(i) + std::size_t(j) * std::size_t(nu);
          std::span<const Interval> cur =
              src ? src->column(c) : std::span<const Interval>(&full_column, 1);
          if (cur.empty()) continue;
          bool dead = false;
          for (std::size_t f = 0; f < F && !dead; ++f) dead = (bins[f] = fast[f].bin(i, j)) < 0;
          if (dead) continue;
          for (std::size_t f = 0; f < F && !cur.empty(); ++f) {
            b.clear();
            fast[f].cut(i, j, bins[f], cur, &pieces, &b);
            std::swap(a, b);
            cur = a;
          }
          if (!cur.empty() && !general.empty()) {
            Vec3 o;
            o[g.u()] = g.box_min[g.u()] + (i + 0.5) * du;
            o[g.v()] = g.box_min[g.v()] + (j + 0.5) * dv;
            o[g.a()] = 0;
            for (const PreparedView* view : general) {
              if (view->misses(o, d, cur.front().lo, cur.back().hi)) {
                cur = {};
                break;
              }
              b.clear();
              view->cut_line(o, d, cur, &b, &scratch);
              std::swap(a, b);
              cur = a;
              if (cur.empty()) break;
            }
          }
          out.insert(out.end(), cur.begin(), cur.end());
          start[c + 1] = uint32_t(cur.size());
        }
      }
    }
  };
  std::vector<std::jthread> workers;
  for (int k = 1; k < T; ++k) workers.emplace_back(work, k);
  work(0);
  workers.clear();
  std::vector<Interval> all;
  if (T == 1) {
    all = std::move(chunk_iv[0]);
  } else {
    std::size_t total = 0;
    for (const auto& v : chunk_iv) total += v.size();
    all.reserve(total);
    for (const auto& v : chunk_iv) all.insert(all.end(), v.begin(), v.end());
  }
  for (std::size_t c = 0; c < columns; ++c) start[c + 1] += start[c];
  if (dst != src) *dst = SegmentSet::empty(g);
  dst->assign(std::move(all), std::move(start));
  return {};
}

}  // namespace

Expected<void> cut(SegmentSet& set, std::span<const View> views, const CutOptions& options) {
  return cut_grid(set.grid(), &set, views, options, &set);
}

Expected<SegmentSet> visual_hull(const GridSpec& grid, std::span<const View> views,
                                 const CutOptions& options) {
  if (auto ok = grid.validate(); !ok) return std::unexpected(ok.error());
  SegmentSet set;
  if (auto ok = cut_grid(grid, nullptr, views, options, &set); !ok) {
    return std::unexpected(ok.error());
  }
  return set;
}

}  // namespace studio::hull
