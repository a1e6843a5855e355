#include "offline/photo_carve.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

#include "hull/crossing_refine.h"
#include "hull/silhouette_cut.h"
#include "offline/view_sampling.h"
#include "parallel_for.h"

namespace studio::offline {
namespace {

// The voxel lattice over the occupied part of the hull's grid: column (i, j) of the grid,
// layer k at t = t0 + (k + 0.5) dt. Index k + nk * (ii + ni * jj), k fastest (a column is
// contiguous).
struct Lattice {
  int i0 = 0, j0 = 0, ni = 0, nj = 0, nk = 0;
  double t0 = 0, dt = 0;
  std::size_t index(int ii, int jj, int k) const {
    return std::size_t(k) + std::size_t(nk) * (std::size_t(ii) + std::size_t(ni) * std::size_t(jj));
  }
  std::size_t size() const { return std::size_t(ni) * std::size_t(nj) * std::size_t(nk); }
};

enum : uint8_t { kEmpty = 0, kFull = 1 };

using detail::parallel_for;

// Where one camera's depth buffer changed between two iterations, over the rectangle either
// buffer drew in (elsewhere both are empty).
class ChangeMap {
 public:
  void build(const DepthBuffer& now, const DepthBuffer& before) {
    const DepthBuffer::Rect a = now.drawn(), b = before.drawn();
    x0_ = std::min(a.x0, b.x0), y0_ = std::min(a.y0, b.y0);
    w_ = std::max(0, std::max(a.x1, b.x1) - x0_ + 1);
    h_ = std::max(0, std::max(a.y1, b.y1) - y0_ + 1);
    changed_.resize(std::size_t(w_) * std::size_t(h_));
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x)
        changed_[std::size_t(y) * w_ + x] = now.at(x0_ + x, y0_ + y) != before.at(x0_ + x, y0_ + y);
  }
  bool at(long x, long y) const {
    x -= x0_, y -= y0_;
    return x >= 0 && y >= 0 && x < w_ && y < h_ && changed_[std::size_t(y) * w_ + std::size_t(x)];
  }

 private:
  int x0_ = 0, y0_ = 0, w_ = 0, h_ = 0;
  std::vector<uint8_t> changed_;
};

}  // namespace

Expected<void> CarveOptions::validate() const {
  if (!(threshold > 0) || !std::isfinite(threshold)) return fail("carve: threshold must be > 0");
  if (min_cameras < 2 || min_cameras > 64) return fail("carve: min_cameras must be 2..64");
  if (max_judges != 0 && (max_judges < min_cameras || max_judges > 64))
    return fail("carve: max_judges must be 0 (all) or min_cameras..64");
  if (!(min_cos >= 0 && min_cos < 1)) return fail("carve: min_cos must be in [0, 1)");
  if (edge_margin_px < 0 || edge_margin_px > 16) return fail("carve: edge_margin_px must be 0..16");
  if (sample_radius_px < 0 || sample_radius_px > 4)
    return fail("carve: sample_radius_px must be 0..4");
  if (!(depth_tolerance > 0 && depth_tolerance < 16))
    return fail("carve: depth_tolerance must be in (0, 16) cells");
  if (max_depth_cells < 0 || max_depth_cells > 1000)
    return fail("carve: max_depth_cells must be 0..1000");
  if (max_iterations < 0 || max_iterations > 10000)
    return fail("carve: max_iterations must be 0..10000");
  if (threads < 1 || threads > 64) return fail("carve: threads must be 1..64");
  if (patch_half < 0 || patch_half > 8) return fail("carve: patch_half must be 0..8");
  if (!(patch_spacing_cells > 0 && patch_spacing_cells <= 4))
    return fail("carve: patch_spacing_cells must be in (0, 4]");
  if (!(patch_min_std > 0) || !std::isfinite(patch_min_std))
    return fail("carve: patch_min_std must be > 0");
  if (!(ncc_threshold >= -1 && ncc_threshold <= 1))
    return fail("carve: ncc_threshold must be in [-1, 1]");
  if (!(ncc_gain >= 0 && ncc_gain <= 2)) return fail("carve: ncc_gain must be in [0, 2]");
  if (!(ncc_min_spread >= 0) || !std::isfinite(ncc_min_spread))
    return fail("carve: ncc_min_spread must be >= 0");
  return {};
}

Expected<CarveResult> photo_carve(const hull::SegmentSet& hull, std::span<const ColourView> views,
                                  const CarveOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  auto sampled = prepare_views(views, options.edge_margin_px);
  if (!sampled) return std::unexpected(sampled.error());
  const std::vector<SampledView>& cams = *sampled;
  const hull::GridSpec& g = hull.grid();
  CarveResult result;
  result.set = hull;

  // The lattice: bounding rectangle of the non-empty columns, t range of their intervals, one
  // empty voxel of padding all round (so every surface voxel has in-range neighbours).
  int i_lo = g.cells_u, i_hi = -1, j_lo = g.cells_v, j_hi = -1;
  double t_lo = std::numeric_limits<double>::max(), t_hi = -t_lo;
  for (int j = 0; j < g.cells_v; ++j) {
    for (int i = 0; i < g.cells_u; ++i) {
      const auto col = hull.column(i, j);
      if (col.empty()) continue;
      i_lo = std::min(i_lo, i), i_hi = std::max(i_hi, i);
      j_lo = std::min(j_lo, j), j_hi = std::max(j_hi, j);
      t_lo = std::min<double>(t_lo, col.front().lo), t_hi = std::max<double>(t_hi, col.back().hi);
    }
  }
  if (i_hi < 0) return result;
  Lattice L;
  L.dt = 0.5 * (g.du() + g.dv());
  L.i0 = i_lo - 1, L.j0 = j_lo - 1;
  L.ni = i_hi - i_lo + 3, L.nj = j_hi - j_lo + 3;
  L.t0 = t_lo - L.dt;
  L.nk = int(std::ceil((t_hi - t_lo) / L.dt)) + 2;
  std::vector<uint8_t> occ(L.size(), kEmpty);
  for (int jj = 1; jj + 1 < L.nj; ++jj) {
    for (int ii = 1; ii + 1 < L.ni; ++ii) {
      for (const hull::Interval& iv : hull.column(L.i0 + ii, L.j0 + jj)) {
        const int ka = std::max(1, int(std::ceil((iv.lo - L.t0) / L.dt - 0.5)));
        const int kb = std::min(L.nk - 2, int(std::ceil((iv.hi - L.t0) / L.dt - 0.5)) - 1);
        for (int k = ka; k <= kb; ++k) occ[L.index(ii, jj, k)] = kFull;
      }
    }
  }
  const auto centre = [&](int ii, int jj, int k) {
    return g.point(L.i0 + ii, L.j0 + jj, L.t0 + (k + 0.5) * L.dt);
  };
  // Depth below the hull surface in cells (chessboard distance, capped): carving stops at
  // max_depth_cells.
  std::vector<uint8_t> depth(L.size(), 255);
  {
    std::vector<std::size_t> frontier, next;
    for (int jj = 1; jj + 1 < L.nj; ++jj)
      for (int ii = 1; ii + 1 < L.ni; ++ii)
        for (int k = 1; k + 1 < L.nk; ++k) {
          const std::size_t x = L.index(ii, jj, k);
          if (!occ[x]) continue;
          ++result.voxels;
          const std::size_t sk = 1, si = std::size_t(L.nk), sj = si * std::size_t(L.ni);
          if (!occ[x - sk] || !occ[x + sk] || !occ[x - si] || !occ[x + si] || !occ[x - sj] ||
              !occ[x + sj]) {
            depth[x] = 0;
            frontier.push_back(x);
          }
        }
    const int cap = std::min(options.max_depth_cells, 254);
    const std::size_t sk = 1, si = std::size_t(L.nk), sj = si * std::size_t(L.ni);
    for (int d = 1; d <= cap && !frontier.empty(); ++d) {
      next.clear();
      for (const std::size_t x : frontier) {
        for (const std::size_t y : {x - sk, x + sk, x - si, x + si, x - sj, x + sj}) {
          if (occ[y] && depth[y] == 255) {
            depth[y] = uint8_t(d);
            next.push_back(y);
          }
        }
      }
      frontier.swap(next);
    }
  }
  const int max_depth = options.max_depth_cells;

  const std::size_t sk = 1, si = std::size_t(L.nk), sj = si * std::size_t(L.ni);
  struct Surface {
    int ii, jj, k;
    std::size_t x;
    Eigen::Vector3d centre;  // in the world
  };
  std::vector<Surface> surface, exposed;  // exposed: the voxels carved in the last iteration
  std::vector<uint8_t> on_surface(L.size(), 0);
  std::vector<uint8_t> carve_flag;
  std::vector<DepthBuffer> buffers(cams.size()), before(cams.size());
  // Each voxel's unnormalised outward normal (below), kept between iterations and updated when a
  // voxel of its 5x5x5 neighbourhood is carved (|component| <= 75). normal_state: 0 not yet
  // computed, 1 as at the voxel's last judgement, 2 changed since.
  std::vector<std::array<int8_t, 3>> normal_cache(L.size());
  std::vector<uint8_t> normal_state(L.size(), 0);
  const double tol = options.depth_tolerance * L.dt;
  // Incremental judging: judged[x] = judged (and kept) with its current normal; changes[c] =
  // the pixels of camera c's depth buffer that changed since the previous iteration.
  std::vector<uint8_t> judged(options.incremental ? L.size() : 0, 0);
  std::vector<uint8_t> deeper_read(options.incremental ? L.size() : 0, 0);  // ... at its last
  // judgement, the patch test looked deeper along the normal
  std::vector<ChangeMap> changes(cams.size());
  for (int iter = 0; iter < options.max_iterations; ++iter) {
    // The surface voxels (an empty 6-neighbour), in lattice order: scanned once; then the
    // previous iteration's that were kept and the occupied neighbours of the carved ones.
    if (iter == 0) {
      for (int jj = 1; jj + 1 < L.nj; ++jj)
        for (int ii = 1; ii + 1 < L.ni; ++ii)
          for (int k = 1; k + 1 < L.nk; ++k) {
            const std::size_t x = L.index(ii, jj, k);
            if (occ[x] && (!occ[x - sk] || !occ[x + sk] || !occ[x - si] || !occ[x + si] ||
                           !occ[x - sj] || !occ[x + sj])) {
              surface.push_back({ii, jj, k, x, centre(ii, jj, k)});
            }
          }
    } else {
      std::vector<Surface> next;
      next.reserve(surface.size() + 6 * exposed.size());
      for (std::size_t n = 0; n < surface.size(); ++n)
        if (!carve_flag[n]) next.push_back(surface[n]);
      for (const Surface& c : exposed) {
        const int nb[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
        for (const auto& d : nb) {
          const int ii = c.ii + d[0], jj = c.jj + d[1], k = c.k + d[2];
          if (ii < 1 || jj < 1 || k < 1 || ii + 1 >= L.ni || jj + 1 >= L.nj || k + 1 >= L.nk)
            continue;
          const std::size_t x = L.index(ii, jj, k);
          if (occ[x] && !on_surface[x]) {
            on_surface[x] = 1;
            next.push_back({ii, jj, k, x, centre(ii, jj, k)});
          }
        }
      }
      std::sort(next.begin(), next.end(),
                [](const Surface& a, const Surface& b) { return a.x < b.x; });
      surface.swap(next);
    }
    for (const Surface& v : surface) on_surface[v.x] = 1;
    // 1. Visibility: every camera's depth buffer of the surface voxels (a splat of the voxel's
    // projected size around its centre).
    const bool incremental = options.incremental && iter > 0;
    if (incremental) std::swap(buffers, before);
    parallel_for(cams.size(), options.threads, [&](std::size_t a, std::size_t b) {
      for (std::size_t c = a; c < b; ++c) {
        buffers[c].reset(cams[c]);
        for (const Surface& s : surface) buffers[c].splat(cams[c], s.centre, L.dt);
        if (incremental) changes[c].build(buffers[c], before[c]);
      }
    });
    // A voxel judged before, with the same normal, whose consulted depth pixels are unchanged in
    // every camera gets the same verdict (kept): everything else its judgement reads is fixed.
    // The pixels are those observe() reads, projected as it projects them: the voxel's own in
    // the cameras facing it (cos >= min_cos) and, where its last judgement ran the patch test
    // deeper, those of the points 1..3 cells deeper along its normal.
    const auto unchanged = [&](const Surface& s, const Eigen::Vector3d& x,
                               const Eigen::Vector3d& normal) {
      if (!incremental || !judged[s.x]) return false;
      const int depths = deeper_read[s.x] ? 3 : 0;
      for (std::size_t c = 0; c < cams.size(); ++c) {
        if (normal.dot((cams[c].centre - x).normalized()) < options.min_cos - 1e-9) continue;
        for (int k = 0; k <= depths; ++k) {
          Eigen::Vector2d p;
          if (!cams[c].project(k == 0 ? x : Eigen::Vector3d(x - k * L.dt * normal), &p)) continue;
          if (changes[c].at(nearest_pixel(p.x()), nearest_pixel(p.y()))) return false;
        }
      }
      return true;
    };
    // 2-3. Photo-consistency of every carvable surface voxel.
    carve_flag.assign(surface.size(), 0);
    std::vector<uint8_t> judged_now(surface.size(), 0);
    parallel_for(surface.size(), options.threads, [&](std::size_t a, std::size_t b) {
      std::vector<Observation> obs, judges;
      std::vector<std::size_t> seen, judges_seen, order;
      std::vector<std::vector<float>> patches;
      for (std::size_t n = a; n < b; ++n) {
        const Surface& s = surface[n];
        if (depth[s.x] > max_depth) continue;
        const bool normal_kept = normal_state[s.x] == 1;
        // Outward normal: away from the occupied voxels of the 5x5x5 neighbourhood.
        if (normal_state[s.x] == 0) {
          int sum[3] = {0, 0, 0};
          for (int dj = -2; dj <= 2; ++dj)
            for (int di = -2; di <= 2; ++di)
              for (int dk = -2; dk <= 2; ++dk) {
                const int ii = s.ii + di, jj = s.jj + dj, k = s.k + dk;
                if (ii < 0 || jj < 0 || k < 0 || ii >= L.ni || jj >= L.nj || k >= L.nk ||
                    !occ[L.index(ii, jj, k)]) {
                  sum[0] += di, sum[1] += dj, sum[2] += dk;
                }
              }
          normal_cache[s.x] = {int8_t(sum[0]), int8_t(sum[1]), int8_t(sum[2])};
        }
        normal_state[s.x] = 1;
        const auto& nc = normal_cache[s.x];
        const Eigen::Vector3d normal_l(nc[0], nc[1], nc[2]);
        if (normal_l.squaredNorm() == 0) continue;
        Eigen::Vector3d normal = Eigen::Vector3d::Zero();
        normal[g.u()] = normal_l.x(), normal[g.v()] = normal_l.y(), normal[g.a()] = normal_l.z();
        normal.normalize();
        const Eigen::Vector3d& x = s.centre;
        if (normal_kept && unchanged(s, x, normal)) continue;
        judged_now[n] = 1;
        if (options.incremental) deeper_read[s.x] = 0;
        obs.clear();
        seen.clear();
        for (std::size_t c = 0; c < cams.size(); ++c) {
          if (auto o = observe(cams[c], buffers[c], x, normal, options.min_cos, tol,
                               options.sample_radius_px)) {
            obs.push_back(*o);
            seen.push_back(c);
          }
        }
        if (int(obs.size()) < options.min_cameras) continue;
        if (options.max_judges > 0 && int(obs.size()) > options.max_judges) {
          // The most frontal judge (the grazing ones carry the spill and the ring light's tint).
          order.resize(obs.size());
          for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
          std::partial_sort(order.begin(), order.begin() + options.max_judges, order.end(),
                            [&](std::size_t i, std::size_t j) { return obs[i].cos > obs[j].cos; });
          order.resize(std::size_t(options.max_judges));
          std::sort(order.begin(), order.end());  // camera order kept
          judges.clear();
          judges_seen.clear();
          for (std::size_t i : order) judges.push_back(obs[i]), judges_seen.push_back(seen[i]);
          obs.swap(judges);
          seen.swap(judges_seen);
        }
        const double spread = colour_spread(obs);
        if (spread > options.threshold) {
          carve_flag[n] = 1;
          continue;
        }
        if (options.patch_half == 0 || spread <= options.ncc_min_spread) continue;
        // Mean NCC over the seeing cameras' patch pairs at y (extra: depth slack, metres).
        const auto patch_score = [&](const Eigen::Vector3d& y,
                                     double extra) -> std::optional<double> {
          patches.clear();
          for (const std::size_t c : seen) {
            auto q = observe_patch(cams[c], buffers[c], y, normal, options.min_cos, tol + extra,
                                   options.patch_half, options.patch_spacing_cells * L.dt);
            if (!q.empty()) patches.push_back(std::move(q));
          }
          double sum = 0;
          int pairs = 0;
          for (std::size_t p = 0; p < patches.size(); ++p)
            for (std::size_t q = p + 1; q < patches.size(); ++q)
              if (auto r = ncc(patches[p], patches[q], options.patch_min_std)) sum += *r, ++pairs;
          if (pairs == 0) return std::nullopt;
          return sum / pairs;
        };
        const auto here = patch_score(x, 0);
        if (!here || *here >= options.ncc_threshold) continue;
        // Carve only towards consistency: some point 1..3 cells deeper along the normal must
        // match clearly better (a phantom voxel has the true surface behind it; a voxel on the
        // true surface has the body's inside, which matches no better).
        if (options.incremental) deeper_read[s.x] = 1;
        for (int k = 1; k <= 3 && !carve_flag[n]; ++k) {
          const auto deeper = patch_score(x - k * L.dt * normal, k * L.dt);
          if (deeper && *deeper > *here + options.ncc_gain) carve_flag[n] = 1;
        }
      }
    });
    std::size_t carved = 0;
    exposed.clear();
    for (std::size_t n = 0; n < surface.size(); ++n) {
      result.judged += judged_now[n];
      if (options.incremental && judged_now[n]) judged[surface[n].x] = 1;
    }
    for (std::size_t n = 0; n < surface.size(); ++n) {
      if (carve_flag[n]) {
        const Surface& s = surface[n];
        occ[s.x] = kEmpty;
        on_surface[s.x] = 0;
        exposed.push_back(s);
        ++carved;
        // Now empty: one more empty neighbour (at offset s - v) in each computed normal around.
        for (int jj = std::max(0, s.jj - 2); jj <= std::min(L.nj - 1, s.jj + 2); ++jj)
          for (int ii = std::max(0, s.ii - 2); ii <= std::min(L.ni - 1, s.ii + 2); ++ii)
            for (int k = std::max(0, s.k - 2); k <= std::min(L.nk - 1, s.k + 2); ++k) {
              const std::size_t v = L.index(ii, jj, k);
              if (normal_state[v] == 0) continue;
              auto& nc = normal_cache[v];
              nc[0] = int8_t(nc[0] + (s.ii - ii)), nc[1] = int8_t(nc[1] + (s.jj - jj)),
              nc[2] = int8_t(nc[2] + (s.k - k));
              normal_state[v] = 2;
            }
      }
    }
    result.iterations = iter + 1;
    result.carved += carved;
    if (carved == 0) break;
  }

  // Back to segments: a hull interval none of whose voxels was carved stays exact; otherwise
  // each run of remaining voxels becomes an interval with carved ends on voxel faces and the
  // hull's own ends where the run reaches them.
  std::vector<std::vector<hull::Interval>> columns(g.columns());
  for (int j = 0; j < g.cells_v; ++j) {
    for (int i = 0; i < g.cells_u; ++i) {
      const auto col = hull.column(i, j);
      auto& out = columns[hull.column_index(i, j)];
      const int ii = i - L.i0, jj = j - L.j0;
      for (const hull::Interval& iv : col) {
        const int ka = std::max(1, int(std::ceil((iv.lo - L.t0) / L.dt - 0.5)));
        const int kb = std::min(L.nk - 2, int(std::ceil((iv.hi - L.t0) / L.dt - 0.5)) - 1);
        bool any_carved = false;
        for (int k = ka; k <= kb; ++k) any_carved |= !occ[L.index(ii, jj, k)];
        if (!any_carved) {
          out.push_back(iv);
          continue;
        }
        for (int k = ka; k <= kb;) {
          if (!occ[L.index(ii, jj, k)]) {
            ++k;
            continue;
          }
          int e = k;
          while (e + 1 <= kb && occ[L.index(ii, jj, e + 1)]) ++e;
          const float lo = k == ka ? iv.lo : float(L.t0 + k * L.dt);
          const float hi = e == kb ? iv.hi : float(L.t0 + (e + 1) * L.dt);
          if (lo < hi) out.push_back({lo, hi});
          k = e + 1;
        }
      }
    }
  }
  result.set = hull::SegmentSet::from_columns(g, columns);
  return result;
}

Expected<hull::Mesh> refined_mesh(const hull::SegmentSet& refined, const hull::SegmentSet& hull,
                                  std::span<const ColourView> views, int threads) {
  hull::Mesh mesh = hull::segment_marching_cubes(refined);
  hull::Mesh exact = mesh;
  std::vector<hull::View> cut_views;
  for (const ColourView& v : views) cut_views.push_back({v.camera, v.mask});
  hull::CutOptions cut;
  cut.threads = threads;
  if (auto ok = hull::refine_crossings(exact, refined, cut_views, cut); !ok) {
    return std::unexpected(ok.error());
  }
  // A vertex between an inside and an outside column of `refined`: keep the exact crossing only
  // where the outside column is outside the hull too (a silhouette made that surface).
  const hull::GridSpec& g = refined.grid();
  for (std::size_t n = 0; n < mesh.vertices.size(); ++n) {
    const Eigen::Vector3f p = mesh.vertices[n];
    if (p == exact.vertices[n]) continue;
    const double fi = (p[g.u()] - g.box_min[g.u()]) / g.du() - 0.5;
    const double fj = (p[g.v()] - g.box_min[g.v()]) / g.dv() - 0.5;
    const double t = p[g.a()];
    // The two columns of the vertex's grid edge; the outside one in `refined`.
    const int ia = int(std::floor(fi + 1e-6)), ja = int(std::floor(fj + 1e-6));
    const bool along_u = std::abs(fi - std::round(fi)) > 0.25;
    const int ib = along_u ? ia + 1 : ia, jb = along_u ? ja : ja + 1;
    const Eigen::Vector3d pa = g.point(ia, ja, t), pb = g.point(ib, jb, t);
    const Eigen::Vector3d outside = refined.contains(pa) ? pb : pa;
    if (!hull.contains(outside)) mesh.vertices[n] = exact.vertices[n];
  }
  hull::compute_normals(mesh);
  return mesh;
}

}  // namespace studio::offline
