#include "projector/mask_geometry.h"

#include <meshoptimizer.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
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
  auto [mesh, error_m] = simplified(input, options);
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

Expected<ActorMesh> grow_mesh(const ActorMesh& input, double margin_m, const GrowOptions& options) {
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return fail("grow mask: margin must be >= 0");
  auto base = simplify_for_mask(input, options);
  if (!base) return std::unexpected(base.error());
  return grow_mask(*base, margin_m, options);
}

Expected<double> dilation_radius_px(const Camera& projector, const ActorMesh& mesh,
                                    double margin_m) {
  if (auto v = mesh.validate(); !v) return std::unexpected(v.error());
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return fail("dilation: margin must be >= 0");
  double z_min = INFINITY;
  for (const auto& v : mesh.vertices) {
    const double z = (projector.cam_from_world * v.cast<double>()).z();
    if (z > 1e-3) z_min = std::min(z_min, z);
  }
  if (!std::isfinite(z_min)) return fail("dilation: the mesh is behind the projector");
  return margin_m * std::max(projector.intrinsics.fx, projector.intrinsics.fy) / z_min;
}

}  // namespace studio::projector
