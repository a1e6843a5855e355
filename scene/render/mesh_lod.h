#pragma once
// Levels of detail of an indexed triangle mesh (no GL): coarser index lists over the same
// vertices, built once at upload with meshoptimizer's edge-collapse simplifier, each with its
// geometric error in the mesh's own units. The renderer draws the coarsest level whose error
// projects below RendererOptions::lod_pixel_error (renderer.cc), so a dense exhibit far from the
// camera costs a fraction of its full vertex and triangle-setup work.
//
// Per-vertex (Gouraud) lighting samples the light at the vertices: a level is kept only when its
// longest edge stays within max(the original's longest edge, max_edge): coplanar grids (a floor
// tessellated for its lighting, a column's shaft) collapse with zero geometric error, and that
// bound keeps them from being flattened into a few long triangles.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace studio::scene_render {

struct LodOptions {
  std::size_t min_triangles = 2048;  // meshes with fewer get no levels
  double max_edge = 0.25;            // longest edge a level may reach (mesh units: metres)
  double reduction = 0.5;            // each level aims at this fraction of the previous one
  double max_error = 0.05;           // relative to the mesh's extent: coarser levels are dropped
};

struct LodLevel {
  std::uint32_t first = 0;  // into MeshLods::indices
  std::uint32_t count = 0;  // indices (3 per triangle)
  float error = 0;          // geometric error, mesh units (level 0: 0)
};

struct MeshLods {
  std::vector<std::uint32_t> indices;  // level 0 (the input), then each coarser level
  std::vector<LodLevel> levels;        // finest first
};

MeshLods build_lods(const std::vector<Eigen::Vector3f>& positions,
                    const std::vector<std::uint32_t>& indices, const LodOptions& options = {});

}  // namespace studio::scene_render
