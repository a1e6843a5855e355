#include "projector/mask_geometry.h"

#include <meshoptimizer.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>

namespace studio::projector {

namespace {

// The triangles of the mesh with at most max_triangles of them (meshoptimizer's clustering and
// edge collapse: the vertices kept are original ones, indexed as in `mesh`; no vertices yet) and
// how far its surface may lie from the original's (metres, the simplifiers' errors times a safety
// factor); the mesh's own triangles when there are few enough.
std::pair<ActorMesh, double> simplified(const ActorMesh& mesh, const GrowOptions& options) {
  if (options.max_triangles == 0 || mesh.triangles.size() <= options.max_triangles)
    return {ActorMesh{{}, mesh.triangles, mesh.capture_ns}, 0.0};
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  static_assert(sizeof(std::array<uint32_t, 3>) == 3 * sizeof(uint32_t));
  const float* xyz = mesh.vertices.front().data();
  const uint32_t* in = mesh.triangles.front().data();
  const std::size_t stride = sizeof(Eigen::Vector3f);
  std::size_t in_count = mesh.triangles.size() * 3;
  float error = 0;
  std::vector<uint32_t> clustered;
  const std::size_t cluster_to = options.cluster_factor * options.max_triangles;
  if (options.presimplify && mesh.triangles.size() > cluster_to) {
    clustered.resize(in_count);
    float sloppy_error = 0;
    const std::size_t k = meshopt_simplifySloppy(
        clustered.data(), in, in_count, xyz, mesh.vertices.size(), stride, cluster_to * 3,
        static_cast<float>(options.max_error), &sloppy_error);
    if (k > 0 && k < in_count) {  // else the edge collapse alone
      in = clustered.data();
      in_count = k;
      error = sloppy_error;
    }
  }
  std::vector<uint32_t> out(in_count);
  std::size_t n = in_count;
  if (in_count > options.max_triangles * 3) {  // clustered to max_triangles: no edge collapse
    float collapse_error = 0;
    n = meshopt_simplify(out.data(), in, in_count, xyz, mesh.vertices.size(), stride,
                         options.max_triangles * 3, static_cast<float>(options.max_error), 0,
                         &collapse_error);
    error += collapse_error;  // the two stages' errors add up (triangle inequality)
  }
  if (n == 0 || (n >= in_count && clustered.empty()))
    return {ActorMesh{{}, mesh.triangles, mesh.capture_ns}, 0.0};
  if (n >= in_count) out.assign(in, in + in_count);
  ActorMesh s;
  s.capture_ns = mesh.capture_ns;
  s.triangles.resize(n / 3);
  for (std::size_t t = 0; t < n / 3; ++t)
    s.triangles[t] = {out[3 * t], out[3 * t + 1], out[3 * t + 2]};
  const double scale = meshopt_simplifyScale(xyz, mesh.vertices.size(), stride);
  return {std::move(s), options.error_safety * error * scale};
}

// The vertices the triangles use, renumbered in order of first use; source[i]: the input index
// of vertex i. A 45k-vertex hull mesh simplified to 3000 triangles keeps ~1.5k: every frame's
// prediction, growth, upload and vertex stage then touch those only.
void compact(const std::vector<Eigen::Vector3f>& vertices, ActorMesh& mesh,
             std::vector<uint32_t>& source) {
  constexpr uint32_t kUnused = ~uint32_t(0);
  std::vector<uint32_t> index(vertices.size(), kUnused);
  source.clear();
  for (auto& tri : mesh.triangles)
    for (uint32_t& v : tri) {
      if (index[v] == kUnused) {
        index[v] = static_cast<uint32_t>(source.size());
        source.push_back(v);
      }
      v = index[v];
    }
  mesh.vertices.resize(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) mesh.vertices[i] = vertices[source[i]];
}

}  // namespace

namespace {

Expected<void> check(const GrowOptions& options) {
  if (!(options.min_cosine > 0 && options.min_cosine <= 1))
    return fail("grow mask: min_cosine must be in (0, 1]");
  if (!(options.max_error >= 0 && options.error_safety >= 1))
    return fail("grow mask: max_error must be >= 0 and error_safety >= 1");
  if (options.cluster_factor < 1 || options.cluster_factor > 1000)
    return fail("grow mask: cluster_factor must be 1..1000");
  return {};
}

}  // namespace

Expected<MaskBase> simplify_for_mask(const ActorMesh& input, const GrowOptions& options) {
  if (auto v = input.validate(); !v) return std::unexpected(v.error());
  if (auto ok = check(options); !ok) return std::unexpected(ok.error());
  // Fewer, larger triangles first: pushed out by the margin, each small triangle of a hull mesh
  // grows to the margin's size, and a renderer rasterises all of them over one another. The
  // simplification's error is added to the push, so the mask still covers the mesh.
  // The outline form rasterises the mesh in the projector's image: whole is cheaper and tighter
  // (GrowOptions::simplify_outline), up to outline_max_triangles (clustered beyond).
  const bool whole = options.projector && !options.simplify_outline;
  GrowOptions bound = options;
  if (whole) {
    bound.max_triangles = options.outline_max_triangles;
    bound.cluster_factor = 1;
    bound.presimplify = true;
  }
  auto [mesh, error_m] = simplified(input, bound);
  MaskBase base{std::move(mesh), error_m, {}};
  compact(input.vertices, base.mesh, base.source);
  return base;
}

Expected<ActorMesh> grow_mask(const MaskBase& base, double margin_m, const GrowOptions& options) {
  const ActorMesh& mesh = base.mesh;
  if (auto v = mesh.validate(); !v) return std::unexpected(v.error());
  if (!(margin_m >= 0) || !std::isfinite(margin_m) || !(base.error_m >= 0))
    return fail("grow mask: margin must be >= 0");
  if (auto ok = check(options); !ok) return std::unexpected(ok.error());
  if (options.projector) {  // the outline form; the push where it cannot be made
    if (auto outline = grow_outline(mesh, margin_m + base.error_m, *options.projector); outline)
      return outline;
    // The push from a whole mesh would draw every small triangle margin-sized: simplified here.
    if (!options.simplify_outline && options.max_triangles > 0 &&
        mesh.triangles.size() > options.max_triangles) {
      GrowOptions push = options;
      push.projector.reset();
      auto simpler = simplify_for_mask(mesh, push);
      if (!simpler) return std::unexpected(simpler.error());
      simpler->error_m += base.error_m;
      return grow_mask(*simpler, margin_m, push);
    }
  }
  margin_m += base.error_m;
  const std::vector<Eigen::Vector3f> normals = vertex_normals(mesh);
  std::vector<float> min_cos(mesh.vertices.size(), 1.0f);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[t[0]];
    const Eigen::Vector3f face = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    const float len = face.norm();
    if (!(len > 0)) continue;
    for (uint32_t v : t) min_cos[v] = std::min(min_cos[v], normals[v].dot(face / len));
  }
  ActorMesh out = mesh;
  for (size_t i = 0; i < out.vertices.size(); ++i) {
    const float c = std::max(min_cos[i], static_cast<float>(options.min_cosine));
    out.vertices[i] += normals[i] * static_cast<float>(margin_m / c);
  }
  return out;
}

namespace {

// Squared Euclidean distance transform of one line (Felzenszwalb & Huttenlocher 2012, the lower
// envelope of the parabolas of the finite values): f in, d out (n values; all infinite when f
// is), v (n) and z (n + 1) scratch.
void edt_1d(const double* f, double* d, int n, int* v, double* z) {
  auto meet = [&](int q, int r) {
    return ((f[q] + double(q) * q) - (f[r] + double(r) * r)) / (2.0 * (q - r));
  };
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -INFINITY;
      z[1] = INFINITY;
      continue;
    }
    double s = meet(q, v[k]);
    while (s <= z[k]) s = meet(q, v[--k]);  // z[0] = -inf ends it
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = INFINITY;
  }
  if (k < 0) {
    std::fill(d, d + n, INFINITY);
    return;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const double dq = q - v[k];
    d[q] = dq * dq + f[v[k]];
  }
}

}  // namespace

Expected<ActorMesh> grow_outline(const ActorMesh& mesh, double margin_m, const Camera& projector,
                                 int cell, int band_px) {  // cell: the smallest cell size
  if (auto v = mesh.validate(); !v) return std::unexpected(v.error());
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return fail("grow mask: margin must be >= 0");
  const Intrinsics& in = projector.intrinsics;
  if (projector.width <= 0 || projector.height <= 0 || !(in.fx > 0) || !(in.fy > 0) || cell < 1 ||
      cell > 16)
    return fail("grow mask: the projector needs a size and focal lengths (cell 1..16)");
  const Eigen::Matrix<double, 3, 4> P = projector.projection_matrix();
  const Eigen::Matrix3d R = projector.cam_from_world.R();
  const Eigen::Vector3d t = projector.cam_from_world.translation;
  const Eigen::Vector3d centre = projector.centre_in_world();
  // Pixels of the vertices; the nearest vertex's distance.
  const std::size_t nv = mesh.vertices.size();
  std::vector<Eigen::Vector2d> px(nv);
  double d_min = INFINITY;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(INFINITY), hi = -lo;
  for (std::size_t i = 0; i < nv; ++i) {
    const Eigen::Vector3d x = mesh.vertices[i].cast<double>();
    const Eigen::Vector3d h = P * x.homogeneous();
    if (!(h.z() > 0.05)) return fail("grow mask: a mesh vertex is behind the projector's near plane");
    px[i] = h.head<2>() / h.z();
    lo = lo.cwiseMin(px[i]);
    hi = hi.cwiseMax(px[i]);
    d_min = std::min(d_min, (x - centre).norm());
  }
  if (!(d_min > 1.001 * margin_m))
    return fail("grow mask: the projector is within the margin of the actor mesh");
  const double a_max = std::asin(margin_m / d_min);
  const double f_max = std::max(in.fx, in.fy), tan_a = std::tan(a_max);
  const double cos_2a = std::cos(2 * a_max), sin_2a = std::sin(2 * a_max);
  // rho at a pixel: f_max tan(a_max) / cos^2(theta + 2 a_max), theta its angle from the axis
  // (cos(theta + b) = cos theta cos b - sin theta sin b, no trigonometry per cell).
  auto rho_at = [&](double u, double v) {
    const double x = (u - in.cx) / in.fx, y = (v - in.cy) / in.fy;
    const double c = 1 / std::sqrt(1 + x * x + y * y), sn = std::sqrt(std::max(0.0, 1 - c * c));
    const double cb = std::max(c * cos_2a - sn * sin_2a, 0.05);
    return f_max * tan_a / (cb * cb);
  };
  // The largest radius the mask needs: at the image pixels near the mesh's image (only pixels
  // of the image are drawn; a ball's centre is within a_max of the pixels it covers, which
  // rho_at's 2 a_max allows for): over its bounding box grown by the radius itself, clamped to
  // the image, until the radius stops growing (the stretch grows away from the axis, so a
  // rectangle's corners and centre bound it).
  double rho_max = 0;
  for (int pass = 0; pass < 8; ++pass) {
    const double g = rho_max;
    const double u0 = std::clamp(lo.x() - g, -0.5, projector.width - 0.5),
                 u1 = std::clamp(hi.x() + g, -0.5, projector.width - 0.5),
                 v0 = std::clamp(lo.y() - g, -0.5, projector.height - 0.5),
                 v1 = std::clamp(hi.y() + g, -0.5, projector.height - 0.5);
    for (double u : {u0, u1, 0.5 * (u0 + u1)})
      for (double v : {v0, v1, 0.5 * (v0 + v1)}) rho_max = std::max(rho_max, rho_at(u, v));
    if (rho_max <= g + 0.25) break;
  }
  // Cells of about a tenth of the radius (2..4 px): the band's slack (a cell's diagonal, and
  // the raster's conservative cell) stays a fraction of it, the grid small.
  cell = std::clamp(int(rho_max / 10), cell, 4);
  const double reach = rho_max + 2.0 * cell;
  // The grid (fine pixel coordinates of its top-left corner; cell (i, j) covers
  // [x0 + i cell, x0 + (i + 1) cell) x [y0 + j cell, ...)): the mesh's image and `reach` round
  // it, clipped to the projector's image and `reach` round that.
  const double x0 = std::floor(std::max(lo.x() - reach, -0.5 - reach));
  const double y0 = std::floor(std::max(lo.y() - reach, -0.5 - reach));
  const double x1 = std::min(hi.x() + reach, projector.width - 0.5 + reach);
  const double y1 = std::min(hi.y() + reach, projector.height - 0.5 + reach);
  ActorMesh out;
  out.capture_ns = mesh.capture_ns;
  out.image_rects = ActorMesh::ImageRects{projector.width, projector.height, {}};
  if (!(x1 > x0 && y1 > y0)) return out;  // the mesh's image and the projector's do not meet
  const int W = int(std::ceil((x1 - x0) / cell)), H = int(std::ceil((y1 - y0) / cell));
  if (double(W) * H > 16e6) return fail("grow mask: the outline grid would be too large");
  // The raster's cells, a byte each (1: set, the mesh's image): the triangles visit them in
  // mesh order, all over the grid, so the smaller the grid the fewer cache misses.
  std::vector<std::uint8_t> set(std::size_t(W) * H, 0);
  const double half = 0.5 * cell;
  auto set_point = [&](const Eigen::Vector2d& p) {
    const int i = int(std::floor((p.x() - x0) / cell)), j = int(std::floor((p.y() - y0) / cell));
    if (i >= 0 && j >= 0 && i < W && j < H) set[std::size_t(j) * W + i] = 1;
  };
  // 1. Conservative raster of every triangle.
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector2d &a = px[tri[0]], &b = px[tri[1]], &c = px[tri[2]];
    // Its cells' range; nothing to do when every cell of it is set already (most triangles of
    // a closed mesh: the far side's lie under the near side's cells).
    const Eigen::Vector2d tlo = a.cwiseMin(b).cwiseMin(c), thi = a.cwiseMax(b).cwiseMax(c);
    const int i0 = std::max(0, int(std::floor((tlo.x() - x0) / cell)));
    const int i1 = std::min(W - 1, int(std::floor((thi.x() - x0) / cell)));
    const int j0 = std::max(0, int(std::floor((tlo.y() - y0) / cell)));
    const int j1 = std::min(H - 1, int(std::floor((thi.y() - y0) / cell)));
    bool open = false;
    for (int j = j0; j <= j1 && !open; ++j)
      for (int i = i0; i <= i1 && !open; ++i) open = set[std::size_t(j) * W + i] == 0;
    if (!open) continue;
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    const double scale = (b - a).squaredNorm() + (c - a).squaredNorm() + 1e-300;
    if (std::abs(area) <= 1e-9 * scale) {  // edge-on: its image is its edges
      for (const auto& [p, q] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}}) {
        const int steps = int(std::ceil((*q - *p).norm() / half)) + 1;
        for (int k = 0; k <= steps; ++k) set_point(*p + (*q - *p) * (double(k) / steps));
      }
      continue;
    }
    const double sign = area > 0 ? 1 : -1;
    // Edge functions e(p) = n . p + k, >= 0 inside; a cell overlaps the half-plane when e at its
    // centre + half (|n.x| + |n.y|) >= 0.
    std::array<Eigen::Vector3d, 3> e;
    const std::array<const Eigen::Vector2d*, 3> v{&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d& p = *v[k];
      const Eigen::Vector2d& q = *v[(k + 1) % 3];
      const Eigen::Vector2d n = sign * Eigen::Vector2d(p.y() - q.y(), q.x() - p.x());
      e[k] = {n.x(), n.y(), -n.dot(p)};
    }
    // (The cell's slack half (|n.x| + |n.y|) folded into each edge's constant; a cell already
    // set by another triangle is not tested again: the same cells either way.)
    std::array<double, 3> slack;
    for (int k = 0; k < 3; ++k)
      slack[k] = e[k].z() + half * (std::abs(e[k].x()) + std::abs(e[k].y()));
    for (int j = j0; j <= j1; ++j) {
      const double w = y0 + (j + 0.5) * cell;
      std::uint8_t* row = set.data() + std::size_t(j) * W;
      for (int i = i0; i <= i1; ++i) {
        if (row[i]) continue;
        const double u = x0 + (i + 0.5) * cell;
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k)
          inside = e[k].x() * u + e[k].y() * w + slack[k] >= 0;
        if (inside) row[i] = 1;
      }
    }
  }
  // 2. Squared distances (in cells) to the nearest set cell: columns, then rows.
  std::vector<double> f(set.size());
  for (std::size_t k = 0; k < set.size(); ++k) f[k] = set[k] ? 0.0 : INFINITY;
  const int n = std::max(W, H);
  std::vector<double> line(n), dist(n), z(n + 1);
  std::vector<int> vv(n);
  for (int i = 0; i < W; ++i) {
    for (int j = 0; j < H; ++j) line[j] = f[std::size_t(j) * W + i];
    edt_1d(line.data(), dist.data(), H, vv.data(), z.data());
    for (int j = 0; j < H; ++j) f[std::size_t(j) * W + i] = dist[j];
  }
  for (int j = 0; j < H; ++j) {
    double* row = f.data() + std::size_t(j) * W;
    std::copy(row, row + W, line.begin());
    edt_1d(line.data(), row, W, vv.data(), z.data());
  }
  // 3-4. The mask's cells as quads 1 m in front of the projector.
  const Eigen::Matrix3d K_inv = in.K().inverse();
  const Eigen::Matrix3d R_t = R.transpose();
  auto at_pixel = [&](double u, double v) {
    const Eigen::Vector3d ray = K_inv * Eigen::Vector3d(u, v, 1);  // z = 1 in the camera frame
    out.vertices.push_back((R_t * (ray / ray.z() - t)).cast<float>());
    return static_cast<uint32_t>(out.vertices.size() - 1);
  };
  const double slack = std::sqrt(2.0) * cell;
  const double inner2 = (f_max * tan_a + slack) * (f_max * tan_a + slack);
  const double outer2 = (rho_max + slack) * (rho_max + slack);
  // 3. Each row's runs of mask cells [begin, end) (rows outside the image have none).
  std::vector<std::array<int, 2>> runs;
  std::vector<std::size_t> row_start(std::size_t(H) + 1, 0);
  for (int j = 0; j < H; ++j) {
    row_start[std::size_t(j)] = runs.size();
    const double vc = y0 + (j + 0.5) * cell;
    if (vc + half < -0.5 || vc - half > projector.height - 0.5) continue;  // outside the image
    const double* row = f.data() + std::size_t(j) * W;
    // rho_at >= f_max tan(a_max) (its 1 / cos^2 >= 1): a cell within that of the mesh's image
    // needs no rho_at, one beyond rho_max is out.
    auto in_mask = [&](int k) {
      const double d2 = row[k] * cell * cell;
      if (d2 <= inner2) return true;
      if (!(d2 <= outer2)) return false;
      const double r = rho_at(x0 + (k + 0.5) * cell, vc) + slack;
      return d2 <= r * r;
    };
    int i = 0;
    while (i < W) {
      if (!in_mask(i)) {
        ++i;
        continue;
      }
      int k = i;
      while (k < W && in_mask(k)) ++k;
      runs.push_back({i, k});
      i = k;
    }
  }
  row_start[std::size_t(H)] = runs.size();
  const auto row_runs = [&](int j) {
    return std::span<const std::array<int, 2>>(runs.data() + row_start[std::size_t(j)],
                                               runs.data() + row_start[std::size_t(j) + 1]);
  };
  // 4. Quads: cells [i0, i1) x [j0, j1), 0.5 px wider each side, 1 m in front of the projector.
  const int ix0 = int(x0), iy0 = int(y0);  // integers (floored above)
  auto quad = [&](int i0, int i1, int j0, int j1) {
    const double u0 = std::max(x0 + i0 * cell - 0.5, -1.0);
    const double u1 = std::min(x0 + i1 * cell + 0.5, projector.width + 0.0);
    const double v0 = std::max(y0 + j0 * cell - 0.5, -1.0);
    const double v1 = std::min(y0 + j1 * cell + 0.5, projector.height + 0.0);
    if (!(u1 > u0 && v1 > v0)) return;
    const uint32_t q0 = at_pixel(u0, v0), q1 = at_pixel(u1, v0), q2 = at_pixel(u1, v1),
                   q3 = at_pixel(u0, v1);
    out.triangles.push_back({q0, q1, q2});
    out.triangles.push_back({q0, q2, q3});
    // The pixel centres inside [u0, u1) x [v0, v1) (its edges lie half-way between centres).
    const int xa = std::max(0, ix0 + i0 * cell), xb = std::min(projector.width, ix0 + i1 * cell + 1);
    const int ya = std::max(0, iy0 + j0 * cell), yb = std::min(projector.height, iy0 + j1 * cell + 1);
    if (xb > xa && yb > ya) out.image_rects->rects.push_back({xa, ya, xb, yb});
  };
  // Bands of rows: the columns every row of a band covers as one tall quad, each row's rest as
  // its own (the same cells: a padded rectangle of cells is the union of its padded cells).
  const int band = std::max(1, band_px / cell);
  std::vector<std::array<int, 2>> common, next, rest;
  // a \ b or a n b of two sorted, disjoint run lists.
  const auto combine = [](std::span<const std::array<int, 2>> a,
                          std::span<const std::array<int, 2>> b, bool intersect,
                          std::vector<std::array<int, 2>>& into) {
    into.clear();
    std::size_t q = 0;
    for (const auto& r : a) {
      int from = r[0];
      while (q < b.size() && b[q][1] <= from) ++q;
      for (std::size_t p = q; p < b.size() && b[p][0] < r[1]; ++p) {
        const int lo = std::max(from, b[p][0]), hi = std::min(r[1], b[p][1]);
        if (intersect) {
          into.push_back({lo, hi});
        } else {
          if (lo > from) into.push_back({from, lo});
          from = hi;
        }
      }
      if (!intersect && from < r[1]) into.push_back({from, r[1]});
    }
  };
  for (int j0 = 0; j0 < H; j0 += band) {
    const int j1 = std::min(H, j0 + band);
    common.assign(row_runs(j0).begin(), row_runs(j0).end());
    for (int j = j0 + 1; j < j1 && !common.empty(); ++j) {
      combine(common, row_runs(j), true, next);
      std::swap(common, next);
    }
    if (j1 - j0 < 2) common.clear();
    for (const auto& r : common) quad(r[0], r[1], j0, j1);
    for (int j = j0; j < j1; ++j) {
      combine(row_runs(j), common, false, rest);
      for (const auto& r : rest) quad(r[0], r[1], j, j + 1);
    }
  }
  return out;
}

Expected<ActorMesh> grow_mesh(const ActorMesh& input, double margin_m, const GrowOptions& options) {
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return fail("grow mask: margin must be >= 0");
  auto base = simplify_for_mask(input, options);
  if (!base) return std::unexpected(base.error());
  return grow_mask(*base, margin_m, options);
}

}  // namespace studio::projector
