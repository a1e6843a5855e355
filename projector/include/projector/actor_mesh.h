#pragma once
// The actor mesh as the projector's mask uses it: the hull's triangle mesh in the studio frame
// (the wire's studio/actor/mesh, converted by the node) with the capture time of the masks that
// built it. Vertex normals are computed here (area-weighted), never trusted from the wire.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/error.h"

namespace studio::projector {

struct ActorMesh {
  std::vector<Eigen::Vector3f> vertices;  // studio frame, metres
  std::vector<std::array<uint32_t, 3>> triangles;
  int64_t capture_ns = 0;  // CLOCK_REALTIME of the frame whose masks built the mesh
  // A mask made in one projector's image (grow_outline): the pixels its quads cover there,
  // exactly, as rectangles — a renderer drawing into an image of that size may clear them
  // instead of rasterising the quads (which overlap at most along 1-px seams, so they need no
  // once-per-pixel depth pass either). Meshes from the hull, files and the vertex push: none.
  struct ImageRects {
    int width = 0, height = 0;  // the projector image's size
    // [x0, x1) x [y0, y1) pixels, image rows top-down, within the image; any order, disjoint
    // apart from 1-px seams.
    std::vector<std::array<int, 4>> rects;
  };
  std::optional<ImageRects> image_rects;

  // Non-empty, every index in range, every vertex finite. One line naming the first problem.
  Expected<void> validate() const;
};

// Unit area-weighted vertex normals (zero for vertices of no or only degenerate triangles).
std::vector<Eigen::Vector3f> vertex_normals(const ActorMesh& mesh);

}  // namespace studio::projector
