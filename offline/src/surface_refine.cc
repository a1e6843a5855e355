#include "offline/surface_refine.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <thread>
#include <unordered_map>
#include <vector>

#include "offline/view_sampling.h"
#include "parallel_for.h"

namespace studio::offline {
namespace {

using detail::parallel_for;

// Each vertex's neighbours, sorted, in one array (compressed rows).
class Adjacency {
 public:
  explicit Adjacency(const std::vector<std::vector<uint32_t>>& lists) : offset_(lists.size() + 1) {
    for (std::size_t n = 0; n < lists.size(); ++n) offset_[n + 1] = offset_[n] + lists[n].size();
    index_.reserve(offset_.back());
    for (const auto& l : lists) index_.insert(index_.end(), l.begin(), l.end());
  }
  std::span<const uint32_t> operator[](std::size_t n) const {
    return {index_.data() + offset_[n], offset_[n + 1] - offset_[n]};
  }

 private:
  std::vector<std::size_t> offset_;
  std::vector<uint32_t> index_;
};

}  // namespace

Expected<void> SurfaceRefineOptions::validate() const {
  if (!(cell > 0 && cell < 1)) return fail("surface refine: cell must be in (0, 1) m");
  if (!(search_in_cells >= 0 && search_in_cells <= 16))
    return fail("surface refine: search_in_cells must be 0..16");
  if (!(search_out_cells >= 0 && search_out_cells <= 16))
    return fail("surface refine: search_out_cells must be 0..16");
  if (!(step_cells > 0.01 && step_cells <= 4))
    return fail("surface refine: step_cells must be in (0.01, 4]");
  if (!(max_in_cells >= 0 && max_in_cells <= 64) || !(max_out_cells >= 0 && max_out_cells <= 64))
    return fail("surface refine: max_in_cells and max_out_cells must be 0..64");
  if (patch_half < 1 || patch_half > 8) return fail("surface refine: patch_half must be 1..8");
  if (!(patch_spacing_cells > 0 && patch_spacing_cells <= 4))
    return fail("surface refine: patch_spacing_cells must be in (0, 4]");
  if (!(patch_min_std > 0) || !std::isfinite(patch_min_std))
    return fail("surface refine: patch_min_std must be > 0");
  if (!(min_cos >= 0 && min_cos < 1)) return fail("surface refine: min_cos must be in [0, 1)");
  if (edge_margin_px < 0 || edge_margin_px > 16)
    return fail("surface refine: edge_margin_px must be 0..16");
  if (min_cameras < 2 || min_cameras > 64) return fail("surface refine: min_cameras must be 2..64");
  if (!(min_ncc >= -1 && min_ncc <= 1)) return fail("surface refine: min_ncc must be in [-1, 1]");
  if (!(min_gain >= 0 && min_gain <= 2)) return fail("surface refine: min_gain must be in [0, 2]");
  if (!(smoothness >= 0 && smoothness <= 1e4) || !(prior > 0 && prior <= 1e4))
    return fail("surface refine: smoothness must be >= 0 and prior > 0");
  if (iterations < 0 || iterations > 100) return fail("surface refine: iterations must be 0..100");
  if (smooth_steps < 0 || smooth_steps > 10000)
    return fail("surface refine: smooth_steps must be 0..10000");
  if (!(depth_tolerance_cells > 0 && depth_tolerance_cells <= 16) || normal_rings < 0 ||
      normal_rings > 50)
    return fail("surface refine: depth_tolerance_cells must be in (0, 16], normal_rings 0..50");
  if (shape_steps < 0 || shape_steps > 1000 || !(shape_lambda > 0 && shape_lambda <= 1) ||
      !(rim_cos >= 0 && rim_cos <= 1))
    return fail(
        "surface refine: shape_steps must be 0..1000, shape_lambda in (0, 1], rim_cos in [0, 1]");
  if (!(rim_band_cells >= 0 && rim_band_cells <= 64))
    return fail("surface refine: rim_band_cells must be in [0, 64]");
  if (shape_order != 1 && shape_order != 2)
    return fail("surface refine: shape_order must be 1 or 2");
  if (shape_order == 2 && shape_lambda > 0.25)
    return fail("surface refine: shape_lambda must be <= 0.25 with shape_order 2 (stability)");
  if (threads < 1 || threads > 64) return fail("surface refine: threads must be 1..64");
  return {};
}

Expected<SurfaceRefineResult> refine_surface(const hull::Mesh& input,
                                             std::span<const ColourView> views,
                                             const SurfaceRefineOptions& o) {
  if (auto ok = o.validate(); !ok) return std::unexpected(ok.error());
  if (o.inside_hull && views.size() > 64)
    return fail("surface refine: inside_hull takes at most 64 cameras");
  auto sampled = prepare_views(views, o.edge_margin_px);
  if (!sampled) return std::unexpected(sampled.error());
  const std::vector<SampledView>& cams = *sampled;
  SurfaceRefineResult result;
  result.mesh = input;
  hull::Mesh& mesh = result.mesh;
  const std::size_t nv = mesh.vertices.size();
  if (nv == 0) return result;

  // Edges (each once per triangle side; a shared edge counts twice, which only scales the
  // smoothness uniformly on a closed mesh).
  std::vector<std::vector<uint32_t>> lists(nv);
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) lists[t[k]].push_back(t[(k + 1) % 3]);
  for (auto& a : lists) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  for (std::size_t n = 0; n < nv; ++n)
    for (const uint32_t m : lists[n])
      if (!std::binary_search(lists[m].begin(), lists[m].end(), uint32_t(n)))
        lists[m].insert(std::lower_bound(lists[m].begin(), lists[m].end(), uint32_t(n)),
                        uint32_t(n));
  // The same lists, contiguous (every step walks them all).
  const Adjacency adjacent(lists);
  lists = {};

  const double cell = o.cell, tol = o.depth_tolerance_cells * cell;
  const int lo = -int(std::lround(o.search_in_cells / o.step_cells));
  const int hi = int(std::lround(o.search_out_cells / o.step_cells));
  std::vector<double> total(nv, 0);  // displacement so far along the (current) normals, metres
  std::vector<double> target(nv, 0), weight(nv, 0), delta(nv, 0), next(nv, 0);
  std::vector<uint8_t> unseen(nv, 0);
  std::vector<DepthBuffer> buffers(cams.size());
  // The search direction: vertex normals averaged over `normal_rings` rings of neighbours (a
  // marching-cubes surface's own normals follow its staircase; the true surface is smooth).
  std::vector<Eigen::Vector3d> normals(nv), tmp(nv);
  const auto smooth_normals = [&] {
    hull::compute_normals(mesh);
    for (std::size_t n = 0; n < nv; ++n) normals[n] = mesh.normals[n].cast<double>();
    for (int r = 0; r < o.normal_rings; ++r) {
      for (std::size_t n = 0; n < nv; ++n) {
        Eigen::Vector3d s = normals[n];
        for (const uint32_t m : adjacent[n]) s += normals[m];
        tmp[n] = s.squaredNorm() > 0 ? s.normalized() : normals[n];
      }
      normals.swap(tmp);
    }
  };
  for (int iter = 0; iter < o.iterations; ++iter) {
    smooth_normals();
    parallel_for(cams.size(), o.threads, [&](std::size_t a, std::size_t b) {
      for (std::size_t c = a; c < b; ++c) {
        buffers[c].reset(cams[c]);
        buffers[c].mesh(cams[c], mesh);
      }
    });
    // 1-2. Data term per vertex.
    parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
      std::vector<std::size_t> seen;
      std::vector<double> score, sums, pair_values;
      std::vector<int> depths;
      std::vector<std::vector<std::vector<float>>> per_cam;
      for (std::size_t n = a; n < b; ++n) {
        target[n] = 0, weight[n] = 0, unseen[n] = 0;
        const Eigen::Vector3d x = mesh.vertices[n].cast<double>();
        const Eigen::Vector3d normal = normals[n];
        if (normal.squaredNorm() < 0.5) continue;
        seen.clear();
        for (std::size_t c = 0; c < cams.size(); ++c)
          if (observe(cams[c], buffers[c], x, normal, o.min_cos, tol)) seen.push_back(c);
        if (int(seen.size()) < o.min_cameras) {
          unseen[n] = 1;
          continue;
        }
        // S(d) for d = k * step, k in [lo, hi]; NaN where no camera pair has structure.
        // The depths of this iteration within the total bounds.
        score.assign(std::size_t(hi - lo + 1), std::nan(""));
        const double lo_bound = -o.max_in_cells * cell - total[n];
        const double hi_bound = o.max_out_cells * cell - total[n];
        depths.clear();
        for (int k = lo; k <= hi; ++k) {
          const double d = k * o.step_cells * cell;
          if (d >= lo_bound - 1e-9 && d <= hi_bound + 1e-9) depths.push_back(k);
        }
        // Every depth is judged by the same cameras (those whose patch stays in their silhouette's
        // interior at all of them) and, for NCC, the same pairs: otherwise a depth whose patches
        // leave the silhouette's border in a camera (the shallow ones, near a contour) would be
        // compared with other cameras than the deep ones, and the best would be biased inward.
        per_cam.clear();
        for (const std::size_t c : seen) {
          std::vector<std::vector<float>> per;
          for (const int k : depths) {
            const double d = k * o.step_cells * cell;
            auto q =
                observe_patch(cams[c], buffers[c], x + d * normal, normal, o.min_cos,
                              tol + std::max(0.0, -d), o.patch_half, o.patch_spacing_cells * cell);
            if (q.empty()) break;
            per.push_back(std::move(q));
          }
          if (per.size() == depths.size() && !per.empty()) per_cam.push_back(std::move(per));
        }
        if (int(per_cam.size()) < o.min_cameras) {
          unseen[n] = 1;
          continue;
        }
        sums.assign(depths.size(), 0.0);
        int pairs = 0;
        for (std::size_t p = 0; p < per_cam.size(); ++p)
          for (std::size_t q = p + 1; q < per_cam.size(); ++q) {
            pair_values.clear();
            for (std::size_t i = 0; i < depths.size(); ++i) {
              const auto& A = per_cam[p][i];
              const auto& B = per_cam[q][i];
              if (o.measure == PhotoMeasure::ncc) {
                const auto r = ncc(A, B, o.patch_min_std);
                if (!r) break;
                pair_values.push_back(*r);
              } else {
                double e = 0;
                for (std::size_t j = 0; j < A.size(); ++j) e += double(A[j] - B[j]) * (A[j] - B[j]);
                pair_values.push_back(e / double(A.size()));
              }
            }
            if (pair_values.size() != depths.size()) continue;
            for (std::size_t i = 0; i < depths.size(); ++i) sums[i] += pair_values[i];
            ++pairs;
          }
        if (pairs > 0)
          for (std::size_t i = 0; i < depths.size(); ++i)
            score[std::size_t(depths[i] - lo)] =
                o.measure == PhotoMeasure::ncc ? sums[i] / pairs : -std::sqrt(sums[i] / pairs);
        int best = -1;
        for (int k = 0; k < int(score.size()); ++k)
          if (!std::isnan(score[k]) && (best < 0 || score[k] > score[best])) best = k;
        if (best < 0) {
          unseen[n] = 1;
          continue;
        }
        // A peak, not a slope: the best depth must have a scored sample on both sides (a score
        // that only keeps rising towards one end of the range is no evidence of a surface there).
        if (o.require_peak && (best == 0 || best + 1 == int(score.size()) ||
                               std::isnan(score[best - 1]) || std::isnan(score[best + 1]))) {
          continue;
        }
        const double s_best = score[best], s_here = score[std::size_t(-lo)];
        double d = (best + lo) * o.step_cells * cell;
        // Evidence strength: the NCC itself, or for SSD 1 (its threshold is max_rms).
        const bool good =
            o.measure == PhotoMeasure::ncc ? s_best >= o.min_ncc : -s_best <= o.max_rms;
        if (!good) continue;
        const double w = o.measure == PhotoMeasure::ncc ? s_best : 1.0;
        if (best + lo == 0) {
          target[n] = 0, weight[n] = w;
          continue;
        }
        if (!std::isnan(s_here) && s_best < s_here + o.min_gain) continue;
        // Sub-step: the parabola through the best sample and its neighbours.
        if (best > 0 && best + 1 < int(score.size()) && !std::isnan(score[best - 1]) &&
            !std::isnan(score[best + 1])) {
          const double a = score[best - 1], c = score[best + 1];
          const double den = a - 2 * s_best + c;
          if (den < 0) d += std::clamp(0.5 * (a - c) / den, -0.5, 0.5) * o.step_cells * cell;
        }
        target[n] = d, weight[n] = w;
      }
    });
    if (iter == 0) {
      result.first_target.assign(target.begin(), target.end());
      result.first_weight.assign(weight.begin(), weight.end());
      for (const auto& d : normals) result.directions.push_back(d.cast<float>());
    }
    // 3. The membrane: Jacobi steps of  (w t + lambda sum_j delta_j) / (w + prior + lambda deg).
    for (std::size_t n = 0; n < nv; ++n) delta[n] = weight[n] > 0 ? target[n] : 0;
    for (int s = 0; s < o.smooth_steps; ++s) {
      parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
        for (std::size_t n = a; n < b; ++n) {
          double sum = 0;
          for (const uint32_t m : adjacent[n]) sum += delta[m];
          const double lam = o.smoothness;
          next[n] = (weight[n] * target[n] + lam * sum) /
                    (weight[n] + o.prior + lam * double(adjacent[n].size()));
        }
      });
      delta.swap(next);
    }
    // 4. Move, within the total bounds.
    result.evidence = 0, result.unseen = 0;
    for (std::size_t n = 0; n < nv; ++n) {
      result.evidence += weight[n] > 0;
      result.unseen += unseen[n];
      const double d = std::clamp(delta[n], -o.max_in_cells * cell - total[n],
                                  o.max_out_cells * cell - total[n]);
      total[n] += d;
      mesh.vertices[n] += (d * normals[n]).cast<float>();
    }
    result.iterations = iter + 1;
  }
  // 5. The shape prior (where the photo term is silent, and it mostly is): Laplacian steps
  // x += lambda (mean of the neighbours - x). On a visual hull this moves the facets that bulge
  // between the silhouette cones inwards, towards the true surface the hull contains. Rim
  // vertices — on a camera's silhouette contour, seen grazing by it — are where the hull touches
  // the true surface (the contour generators): they are anchored, so the smoothed surface keeps
  // the silhouettes' support there.
  if (o.shape_steps > 0) {
    smooth_normals();
    std::vector<uint8_t> anchored(nv, 0);
    // The facet that anchored a vertex: camera, contour pixel, depth along the camera's axis.
    struct Facet {
      uint32_t camera = 0;
      int32_t px = 0, py = 0;
      float depth = 0;
    };
    std::vector<Facet> facet(o.rim_band_cells > 0 ? nv : 0);
    if (o.anchor_rims) {
      parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
        for (std::size_t n = a; n < b; ++n) {
          const Eigen::Vector3d x = mesh.vertices[n].cast<double>();
          for (std::size_t c = 0; c < views.size() && !anchored[n]; ++c) {
            const Camera& cam = *views[c].camera;
            if (std::abs(normals[n].dot((cams[c].centre - x).normalized())) > o.rim_cos) continue;
            Eigen::Vector2d p;
            Eigen::Vector3d xc;
            if (!cams[c].project(x, &p, &xc)) continue;
            const int px = int(nearest_pixel(p.x())), py = int(nearest_pixel(p.y()));
            if (px < 1 || py < 1 || px + 1 >= cam.width || py + 1 >= cam.height) continue;
            int inside = 0;
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) inside += views[c].mask->contains(px + dx, py + dy);
            if (inside > 0 && inside < 9) {
              anchored[n] = 1;
              if (o.rim_band_cells > 0) {
                facet[n] = {uint32_t(c), int32_t(px), int32_t(py), float(xc.z())};
              }
            }
          }
        }
      });
      if (o.rim_band_cells > 0) {
        // The extent of each (camera, contour pixel) facet strip along its ray; keep the anchors
        // near its middle.
        std::unordered_map<uint64_t, std::pair<float, float>> extent;
        const auto key = [](const Facet& f) {
          return (uint64_t(f.camera) << 40) ^ (uint64_t(uint32_t(f.py)) << 20) ^
                 uint64_t(uint32_t(f.px));
        };
        for (std::size_t n = 0; n < nv; ++n) {
          if (!anchored[n]) continue;
          auto [it, fresh] = extent.try_emplace(key(facet[n]), facet[n].depth, facet[n].depth);
          if (!fresh) {
            it->second.first = std::min(it->second.first, facet[n].depth);
            it->second.second = std::max(it->second.second, facet[n].depth);
          }
        }
        for (std::size_t n = 0; n < nv; ++n) {
          if (!anchored[n]) continue;
          const auto& [lo, hi] = extent.at(key(facet[n]));
          anchored[n] =
              std::abs(facet[n].depth - 0.5f * (lo + hi)) <= float(o.rim_band_cells * cell);
        }
      }
    }
    // For inside_hull: the cameras (bit c) whose silhouette contains x's projection (nearest
    // pixel), and whether x is inside all of the silhouettes `bits` (stops at the first miss).
    // (SampledView::project, and the masks as dense bytes: the test runs ~20 times per vertex
    // and step.)
    std::vector<Mask> dense(o.inside_hull ? views.size() : 0);
    for (std::size_t c = 0; c < dense.size(); ++c) dense[c] = views[c].mask->to_mask();
    const auto in_silhouette = [&](std::size_t c, const Eigen::Vector3f& x) {
      Eigen::Vector2d p;
      if (!cams[c].project(x.cast<double>(), &p)) return false;
      const long px = nearest_pixel(p.x()), py = nearest_pixel(p.y());
      return px >= 0 && py >= 0 && px < dense[c].width() && py < dense[c].height() &&
             dense[c](int(px), int(py)) != 0;
    };
    const auto silhouettes = [&](const Eigen::Vector3f& x, uint64_t skip = 0) {
      uint64_t bits = 0;
      for (std::size_t c = 0; c < views.size(); ++c)
        if (!(skip >> c & 1) && in_silhouette(c, x)) bits |= uint64_t(1) << c;
      return bits;
    };
    const auto inside_all = [&](uint64_t bits, const Eigen::Vector3f& x) {
      for (std::size_t c = 0; c < views.size(); ++c)
        if ((bits >> c & 1) && !in_silhouette(c, x)) return false;
      return true;
    };
    // Per vertex, the silhouettes its current position is inside (kept up to date as it moves:
    // a move is only taken inside all of them, so only the others are tested again).
    std::vector<uint64_t> inside(o.inside_hull ? nv : 0);
    if (o.inside_hull)
      parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
        for (std::size_t n = a; n < b; ++n) inside[n] = silhouettes(mesh.vertices[n]);
      });
    std::vector<Eigen::Vector3f> moved(nv), lap(nv);
    const auto umbrella = [&](const std::vector<Eigen::Vector3f>& f, std::size_t n) {
      Eigen::Vector3f m = Eigen::Vector3f::Zero();
      for (const uint32_t j : adjacent[n]) m += f[j];
      return Eigen::Vector3f(m / float(adjacent[n].size()) - f[n]);
    };
    for (int step = 0; step < o.shape_steps; ++step) {
      if (o.shape_order == 2)
        parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
          for (std::size_t n = a; n < b; ++n)
            lap[n] = adjacent[n].empty() ? Eigen::Vector3f::Zero() : umbrella(mesh.vertices, n);
        });
      parallel_for(nv, o.threads, [&](std::size_t a, std::size_t b) {
        for (std::size_t n = a; n < b; ++n) {
          moved[n] = mesh.vertices[n];
          if (anchored[n] || adjacent[n].empty()) continue;
          Eigen::Vector3f d =
              o.shape_order == 2
                  ? Eigen::Vector3f(-float(o.shape_lambda) * umbrella(lap, n))
                  : Eigen::Vector3f(float(o.shape_lambda) * umbrella(mesh.vertices, n));
          if (!o.inside_hull) {
            moved[n] += d;
            continue;
          }
          const uint64_t before = inside[n];
          for (int halve = 0; halve < 4; ++halve, d *= 0.5f)
            if (inside_all(before, mesh.vertices[n] + d)) {
              moved[n] += d;
              // Still inside `before`; other silhouettes it may have entered:
              inside[n] = before | silhouettes(moved[n], before);
              break;
            }
        }
      });
      mesh.vertices.swap(moved);
    }
    for (std::size_t n = 0; n < nv; ++n) result.anchored += anchored[n];
  }
  hull::compute_normals(mesh);
  double shift = 0;
  for (std::size_t n = 0; n < nv; ++n)
    shift += double((mesh.vertices[n] - input.vertices[n]).norm());
  result.mean_shift = shift / double(nv);
  return result;
}

}  // namespace studio::offline
