#include "projector/mask_geometry.h"

#include <meshoptimizer.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace studio::projector {

namespace {

// The mesh with at most max_triangles triangles (meshoptimizer's edge collapse: the vertices
// kept are original ones) and how far its surface may lie from the original's (metres, the
// simplifier's error times a safety factor); the mesh itself when it is small enough.
std::pair<ActorMesh, double> simplified(const ActorMesh& mesh, const GrowOptions& options) {
  if (options.max_triangles == 0 || mesh.triangles.size() <= options.max_triangles)
    return {mesh, 0.0};
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float));
  static_assert(sizeof(std::array<uint32_t, 3>) == 3 * sizeof(uint32_t));
  const float* xyz = mesh.vertices.front().data();
  const uint32_t* in = mesh.triangles.front().data();
  const std::size_t stride = sizeof(Eigen::Vector3f);
  std::size_t in_count = mesh.triangles.size() * 3;
  float error = 0;
  std::vector<uint32_t> clustered;
  if (options.presimplify && mesh.triangles.size() > 4 * options.max_triangles) {
    clustered.resize(in_count);
    float sloppy_error = 0;
    const std::size_t k = meshopt_simplifySloppy(
        clustered.data(), in, in_count, xyz, mesh.vertices.size(), stride,
        4 * options.max_triangles * 3, static_cast<float>(options.max_error), &sloppy_error);
    if (k > 0 && k < in_count) {  // else the edge collapse alone
      in = clustered.data();
      in_count = k;
      error = sloppy_error;
    }
  }
  std::vector<uint32_t> out(in_count);
  float collapse_error = 0;
  const std::size_t n = meshopt_simplify(out.data(), in, in_count, xyz, mesh.vertices.size(),
                                         stride, options.max_triangles * 3,
                                         static_cast<float>(options.max_error), 0, &collapse_error);
  error += collapse_error;  // the two stages' errors add up (triangle inequality)
  if (n == 0 || (n >= in_count && clustered.empty())) return {mesh, 0.0};
  if (n >= in_count) out.assign(in, in + in_count);
  ActorMesh s = mesh;
  s.triangles.resize(n / 3);
  for (std::size_t t = 0; t < n / 3; ++t)
    s.triangles[t] = {out[3 * t], out[3 * t + 1], out[3 * t + 2]};
  const double scale = meshopt_simplifyScale(xyz, mesh.vertices.size(), stride);
  return {std::move(s), options.error_safety * error * scale};
}

}  // namespace

namespace {

Expected<void> check(const GrowOptions& options) {
  if (!(options.min_cosine > 0 && options.min_cosine <= 1))
    return fail("grow mask: min_cosine must be in (0, 1]");
  if (!(options.max_error >= 0 && options.error_safety >= 1))
    return fail("grow mask: max_error must be >= 0 and error_safety >= 1");
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
  return MaskBase{std::move(mesh), error_m};
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
