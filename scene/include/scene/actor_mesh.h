#pragma once
// The live actor's mesh as a renderer draws it (the ActorMesh stream of the hull, in the studio
// frame): vertices, per-vertex normals, triangles (indices into vertices, counter-clockwise seen
// from outside) and optional per-vertex colours (RGB in [0, 1]; empty = the actor node's
// material colour).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"

namespace studio::scene {

struct ActorMesh {
  std::string actor_id;
  std::int64_t frame = 0;
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> normals;  // empty or one per vertex
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Eigen::Vector3f> colours;  // empty or one per vertex

  // Finite vertices, indices < vertices.size(), normals / colours empty or one per vertex.
  Expected<void> validate() const;
  // Area-weighted vertex normals from the triangles (replaces `normals`).
  void compute_normals();
};

}  // namespace studio::scene
