#include "projector/mask_geometry.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace studio::projector {

Expected<ActorMesh> grow_mesh(const ActorMesh& mesh, double margin_m, const GrowOptions& options) {
  if (auto v = mesh.validate(); !v) return std::unexpected(v.error());
  if (!(margin_m >= 0) || !std::isfinite(margin_m)) return fail("grow mask: margin must be >= 0");
  if (!(options.min_cosine > 0 && options.min_cosine <= 1))
    return fail("grow mask: min_cosine must be in (0, 1]");
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
