#include "scene/actor_mesh.h"

#include <Eigen/Geometry>

namespace studio::scene {

Expected<void> ActorMesh::validate() const {
  for (const auto& v : vertices)
    if (!v.allFinite()) return fail("actor mesh: vertex is not finite");
  if (!normals.empty() && normals.size() != vertices.size())
    return fail("actor mesh: " + std::to_string(normals.size()) + " normals for " +
                std::to_string(vertices.size()) + " vertices");
  if (!colours.empty() && colours.size() != vertices.size())
    return fail("actor mesh: " + std::to_string(colours.size()) + " colours for " +
                std::to_string(vertices.size()) + " vertices");
  for (const auto& t : triangles)
    for (std::uint32_t i : t)
      if (i >= vertices.size()) return fail("actor mesh: triangle index out of range");
  return {};
}

void ActorMesh::compute_normals() {
  normals.assign(vertices.size(), Eigen::Vector3f::Zero());
  for (const auto& t : triangles) {
    const Eigen::Vector3f n =
        (vertices[t[1]] - vertices[t[0]]).cross(vertices[t[2]] - vertices[t[0]]);  // |n| = 2 area
    for (std::uint32_t i : t) normals[i] += n;
  }
  for (auto& n : normals) {
    const float l = n.norm();
    n = l > 0 ? Eigen::Vector3f(n / l) : Eigen::Vector3f::UnitY();
  }
}

}  // namespace studio::scene
