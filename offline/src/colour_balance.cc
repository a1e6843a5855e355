#include "offline/colour_balance.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>

#include "hull/crossing_refine.h"
#include "offline/view_sampling.h"
#include "parallel_for.h"

namespace studio::offline {

Expected<void> ColourBalanceOptions::validate() const {
  if (!(min_cos >= -1 && min_cos <= 1)) return fail("colour balance: min_cos outside [-1, 1]");
  if (edge_margin_px < 0 || edge_margin_px > 64)
    return fail("colour balance: edge_margin_px outside [0, 64]");
  if (!(depth_tolerance >= 0 && depth_tolerance < 1))
    return fail("colour balance: depth_tolerance outside [0, 1) m");
  if (!(max_cos_difference >= 0 && max_cos_difference <= 2))
    return fail("colour balance: max_cos_difference outside [0, 2]");
  if (min_samples < 1) return fail("colour balance: min_samples must be >= 1");
  if (!(min_level >= 1 && max_level > min_level && max_level <= 255))
    return fail("colour balance: need 1 <= min_level < max_level <= 255");
  if (!(max_gain > 1 && max_gain <= 16)) return fail("colour balance: max_gain outside (1, 16]");
  if (!(tolerance >= 0 && tolerance < 1)) return fail("colour balance: tolerance outside [0, 1)");
  if (threads < 1 || threads > 64) return fail("colour balance: threads outside [1, 64]");
  return {};
}

namespace {

// Area-weighted vertex normals (the mesh's own may be absent or stale).
std::vector<Eigen::Vector3d> vertex_normals(const hull::Mesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(),
                          b = mesh.vertices[t[1]].cast<double>(),
                          c = mesh.vertices[t[2]].cast<double>();
    const Eigen::Vector3d f = (b - a).cross(c - a);  // twice the area, outward (CCW)
    for (uint32_t i : t) n[i] += f;
  }
  for (auto& v : n) {
    const double l = v.norm();
    v = l > 0 ? Eigen::Vector3d(v / l) : Eigen::Vector3d::Zero();
  }
  return n;
}

// Median of v (reordered).
double median(std::vector<float>& v) {
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(m), v.end());
  double med = v[m];
  if (v.size() % 2 == 0)
    med = 0.5 * (med + *std::max_element(v.begin(), v.begin() + std::ptrdiff_t(m)));
  return med;
}

}  // namespace

ColourBalanceEstimator::ColourBalanceEstimator(std::size_t cameras,
                                               const ColourBalanceOptions& options)
    : cameras_(cameras), options_(options), ratios_(cameras * cameras) {}

Expected<void> ColourBalanceEstimator::add(const hull::Mesh& mesh,
                                           std::span<const ColourView> views) {
  if (auto ok = options_.validate(); !ok) return std::unexpected(ok.error());
  if (views.size() != cameras_)
    return fail("colour balance: " + std::to_string(views.size()) + " views for " +
                std::to_string(cameras_) + " cameras");
  // The views of this frame (absent ones skipped) and their cameras' indices.
  std::vector<ColourView> present;
  std::vector<int> index;
  for (std::size_t c = 0; c < views.size(); ++c) {
    const ColourView& v = views[c];
    if (!v.camera && !v.mask && v.image.width() == 0) continue;  // absent this frame
    if (!v.camera) return fail("colour balance: view " + std::to_string(c) + " has no camera");
    present.push_back(v);
    index.push_back(int(c));
  }
  if (present.size() < 2) {  // nothing to compare: a frame with no pair
    ++frames_;
    return {};
  }
  auto prepared = prepare_views(present, options_.edge_margin_px);
  if (!prepared) return std::unexpected(prepared.error());
  const std::vector<SampledView>& sv = *prepared;
  const int n = int(sv.size());
  const int all = int(cameras_);
  std::vector<DepthBuffer> depth(sv.size());
  for (std::size_t c = 0; c < sv.size(); ++c) {
    depth[c].reset(sv[c]);
    depth[c].mesh(sv[c], mesh);
  }
  const std::vector<Eigen::Vector3d> normals = vertex_normals(mesh);
  // Per ordered pair (i < j, the cameras' indices) and channel: log(colour_i) - log(colour_j) of
  // the shared points.
  const auto pair_index = [all](int i, int j) { return std::size_t(i) * std::size_t(all) + j; };
  std::mutex merge;
  std::vector<std::array<std::vector<float>, 3>> fresh(ratios_.size());  // this frame's
  const float lo = float(options_.min_level), hi = float(options_.max_level);
  detail::parallel_for(mesh.vertices.size(), options_.threads, [&](std::size_t a, std::size_t b) {
    std::vector<std::array<std::vector<float>, 3>> local(ratios_.size());
    std::size_t seen_twice = 0;
    std::vector<std::pair<int, Observation>> obs;
    for (std::size_t v = a; v < b; ++v) {
      if (normals[v].isZero()) continue;
      const Eigen::Vector3d x = mesh.vertices[v].cast<double>();
      obs.clear();
      for (int c = 0; c < n; ++c)
        if (auto o = observe(sv[std::size_t(c)], depth[std::size_t(c)], x, normals[v],
                             options_.min_cos, options_.depth_tolerance))
          obs.emplace_back(index[std::size_t(c)], *o);
      if (obs.size() < 2) continue;
      ++seen_twice;
      for (std::size_t p = 0; p < obs.size(); ++p)
        for (std::size_t q = p + 1; q < obs.size(); ++q) {
          if (std::abs(obs[p].second.cos - obs[q].second.cos) > options_.max_cos_difference)
            continue;
          for (int k = 0; k < 3; ++k) {
            const float ci = obs[p].second.colour[k], cj = obs[q].second.colour[k];
            if (ci < lo || cj < lo || ci > hi || cj > hi) continue;
            local[pair_index(obs[p].first, obs[q].first)][std::size_t(k)].push_back(std::log(ci) -
                                                                                    std::log(cj));
          }
        }
    }
    std::lock_guard g(merge);
    points_ += seen_twice;
    for (std::size_t i = 0; i < local.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        auto& to = fresh[i][std::size_t(k)];
        const auto& from = local[i][std::size_t(k)];
        to.insert(to.end(), from.begin(), from.end());
      }
  });
  // The merge order depends on the threads; the medians and counts do not. The window
  // (max_pair_samples) drops older frames' samples first, never this frame's.
  const std::size_t cap = options_.max_pair_samples;
  for (std::size_t i = 0; i < ratios_.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      auto& to = ratios_[i][std::size_t(k)];
      const auto& from = fresh[i][std::size_t(k)];
      if (cap > 0 && to.size() + from.size() > cap) {
        const std::size_t drop = std::min(to.size(), to.size() + from.size() - cap);
        to.erase(to.begin(), to.begin() + std::ptrdiff_t(drop));
      }
      to.insert(to.end(), from.begin(), from.end());
    }
  ++frames_;
  return {};
}

Expected<void> ColourBalanceEstimator::add(const hull::GridSpec& grid,
                                           std::span<const ColourView> views,
                                           const hull::CutOptions& cut, int columns) {
  if (columns < 1) return fail("colour balance: columns must be >= 1");
  hull::GridSpec coarse = grid;
  coarse.cells_u = std::min(grid.cells_u, columns);
  coarse.cells_v = std::min(grid.cells_v, columns);
  std::vector<hull::View> silhouettes;
  for (const ColourView& v : views) silhouettes.push_back({v.camera, v.mask});
  auto set = hull::visual_hull(coarse, silhouettes, cut);
  if (!set) return std::unexpected(set.error());
  hull::MeshOptions mo;
  mo.normals = false;  // add() computes its own
  hull::Mesh mesh = hull::segment_marching_cubes(*set, mo);
  if (auto ok = hull::refine_crossings(mesh, *set, silhouettes, cut, false); !ok)
    return std::unexpected(ok.error());
  return add(mesh, views);
}

ColourBalance ColourBalanceEstimator::solve() {
  const int n = int(cameras_);
  const auto pair_index = [n](int i, int j) { return std::size_t(i) * std::size_t(n) + j; };
  ColourBalance out;
  out.points = points_;
  out.frames = frames_;
  out.gains.assign(cameras_, Eigen::Vector3f::Ones());
  std::vector<std::array<double, 3>> log_gain(cameras_, {0, 0, 0});
  struct Edge {
    int i, j;
    double w;
    std::array<double, 3> m;  // median log(colour_i / colour_j) per channel
  };
  std::vector<Edge> edges;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      auto& r = ratios_[pair_index(i, j)];
      const std::size_t count = std::min({r[0].size(), r[1].size(), r[2].size()});
      if (count < std::size_t(options_.min_samples)) continue;
      Edge e{i, j, double(count), {}};
      for (int k = 0; k < 3; ++k) e.m[std::size_t(k)] = median(r[std::size_t(k)]);
      edges.push_back(e);
    }
  out.pairs = int(edges.size());
  // Connected sets of cameras (union-find over the used pairs).
  std::vector<int> root(cameras_);
  std::iota(root.begin(), root.end(), 0);
  const auto find = [&](int i) {
    while (root[std::size_t(i)] != i)
      i = root[std::size_t(i)] = root[std::size_t(root[std::size_t(i)])];
    return i;
  };
  for (const Edge& e : edges) root[std::size_t(find(e.i))] = find(e.j);
  out.linked_set.assign(cameras_, -1);
  {
    std::vector<int> smallest(cameras_, n);  // per root: the smallest index in its set
    for (int c = 0; c < n; ++c)
      smallest[std::size_t(find(c))] = std::min(smallest[std::size_t(find(c))], c);
    for (const Edge& e : edges)
      out.linked_set[std::size_t(e.i)] = out.linked_set[std::size_t(e.j)] =
          smallest[std::size_t(find(e.i))];
  }
  // Least squares per channel: w (g_i - g_j + m_ij)^2 over the edges (g = log gain, so that
  // the balanced colours agree: log c_i + g_i = log c_j + g_j), plus sum g = 0 per connected set.
  const int rows = int(edges.size()) + n;
  for (int k = 0; k < 3 && n > 0; ++k) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, n);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(rows);
    for (std::size_t r = 0; r < edges.size(); ++r) {
      const double s = std::sqrt(edges[r].w);
      A(Eigen::Index(r), edges[r].i) = s;
      A(Eigen::Index(r), edges[r].j) = -s;
      y(Eigen::Index(r)) = -s * edges[r].m[std::size_t(k)];
    }
    for (int c = 0; c < n; ++c) A(Eigen::Index(edges.size()) + find(c), c) = 1;  // gauge rows
    const Eigen::VectorXd g = A.colPivHouseholderQr().solve(y);
    const double cap = std::log(options_.max_gain);
    for (int c = 0; c < n; ++c) {
      const bool linked = std::any_of(edges.begin(), edges.end(),
                                      [c](const Edge& e) { return e.i == c || e.j == c; });
      const double l = linked && std::isfinite(g(c)) ? std::clamp(g(c), -cap, cap) : 0.0;
      log_gain[std::size_t(c)][std::size_t(k)] = l;
      out.gains[std::size_t(c)][k] = float(std::exp(l));
    }
  }
  std::vector<float> left;
  for (const Edge& e : edges)
    for (int k = 0; k < 3; ++k)
      left.push_back(
          float(std::abs(e.m[std::size_t(k)] + log_gain[std::size_t(e.i)][std::size_t(k)] -
                         log_gain[std::size_t(e.j)][std::size_t(k)])));
  out.residual = left.empty() ? 0 : median(left);
  out.estimated = out.gains;
  out.applied = std::any_of(out.gains.begin(), out.gains.end(), [&](const Eigen::Vector3f& g) {
    return (g.array() - 1).abs().maxCoeff() > float(options_.tolerance);
  });
  if (!out.applied)
    for (Eigen::Vector3f& g : out.gains) g = Eigen::Vector3f::Ones();
  return out;
}

Expected<ColourBalance> estimate_colour_balance(const hull::Mesh& mesh,
                                                std::span<const ColourView> views,
                                                const ColourBalanceOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  if (views.empty()) return fail("no camera views");
  ColourBalanceEstimator e(views.size(), options);
  if (auto ok = e.add(mesh, views); !ok) return std::unexpected(ok.error());
  return e.solve();
}

Expected<ColourBalance> estimate_colour_balance(const hull::GridSpec& grid,
                                                std::span<const ColourView> views,
                                                const hull::CutOptions& cut, int columns,
                                                const ColourBalanceOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  if (views.empty()) return fail("no camera views");
  ColourBalanceEstimator e(views.size(), options);
  if (auto ok = e.add(grid, views, cut, columns); !ok) return std::unexpected(ok.error());
  return e.solve();
}

std::vector<ColourView> apply_colour_balance(std::span<const ColourView> views,
                                             const ColourBalance& balance,
                                             std::vector<Image<Rgb8>>* images) {
  images->clear();
  images->reserve(views.size());  // the views below point into it: no reallocation
  std::vector<ColourView> out(views.begin(), views.end());
  for (std::size_t c = 0; c < views.size() && c < balance.gains.size(); ++c) {
    const Eigen::Vector3f g = balance.gains[c];
    if (g == Eigen::Vector3f::Ones()) continue;
    const ImageView<const Rgb8>& in = views[c].image;
    Image<Rgb8>& img = images->emplace_back(in.width(), in.height());
    std::array<std::array<uint8_t, 256>, 3> lut;  // per channel: round(v * g), clamped
    for (int k = 0; k < 3; ++k)
      for (int v = 0; v < 256; ++v)
        lut[std::size_t(k)][std::size_t(v)] =
            uint8_t(std::clamp(std::lround(double(v) * g[k]), 0L, 255L));
    for (int y = 0; y < in.height(); ++y) {
      const Rgb8* src = in.row(y);
      Rgb8* dst = &img(0, y);
      for (int x = 0; x < in.width(); ++x)
        dst[x] = {lut[0][src[x].r], lut[1][src[x].g], lut[2][src[x].b]};
    }
    out[c].image = img.view();
  }
  return out;
}

}  // namespace studio::offline
