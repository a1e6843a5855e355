#include "projector/actor_mesh.h"

#include <Eigen/Geometry>

#include "text.h"

namespace studio::projector {

Expected<void> ActorMesh::validate() const {
  if (vertices.empty() || triangles.empty()) {
    return fail(
        text("actor mesh: empty (%zu vertices, %zu triangles)", vertices.size(), triangles.size()));
  }
  for (size_t i = 0; i < vertices.size(); ++i)
    if (!vertices[i].allFinite()) return fail(text("actor mesh: vertex %zu is not finite", i));
  for (size_t i = 0; i < triangles.size(); ++i)
    for (uint32_t v : triangles[i])
      if (v >= vertices.size())
        return fail(text("actor mesh: triangle %zu names vertex %u of %zu", i, v, vertices.size()));
  return {};
}

std::vector<Eigen::Vector3f> vertex_normals(const ActorMesh& mesh) {
  std::vector<Eigen::Vector3f> n(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3f& a = mesh.vertices[t[0]];
    const Eigen::Vector3f face = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
    for (uint32_t v : t) n[v] += face;  // |face| = twice the area: area weighting
  }
  for (auto& v : n) {
    const float len = v.norm();
    v = len > 0 ? Eigen::Vector3f(v / len) : Eigen::Vector3f::Zero();
  }
  return n;
}

}  // namespace studio::projector
