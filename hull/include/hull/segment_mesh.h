#pragma once
// Segment marching cubes (TCSVT 2004 §IV-C): a triangle mesh made directly from the segment set,
// with no voxel volume in between.
//
// Cells lie between 2x2 neighbouring columns (the grid is padded with a ring of empty columns so
// surfaces close at the box sides). Along the continuous axis a cell is cut at the interval end
// points of its four columns — the exact end points, never a sampled layer — into slabs of
// constant corner occupancy. In each slab the cross-section is the marching-squares region of
// the four corners (crossings at half cell across the columns; the ambiguous diagonal case keeps
// the two corners apart); its contour, extruded over the slab, gives the walls; at each end point
// the change of the cross-section gives a horizontal cap. Every vertex lies on a vertical line
// (a column, a mid-edge between two columns or a cell centre) at an interval end point, and the
// vertices on each line are shared by every face that touches it, so the mesh is watertight and
// consistently oriented (outward normals, counter-clockwise triangles). Normals are area-weighted
// vertex normals.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "hull/segment_set.h"

namespace studio::hull {

struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> normals;  // unit, one per vertex
  std::vector<std::array<uint32_t, 3>> triangles;

  bool empty() const { return triangles.empty(); }
  // Enclosed volume by the divergence theorem (positive for outward orientation).
  double volume() const;
};

struct MeshOptions {
  // Vertex normals (compute_normals). A caller that moves the vertices afterwards and recomputes
  // them (refine_crossings) skips this pass: mesh.normals is then empty.
  bool normals = true;
  // 2: the cells are split into two halves of rows meshed on two threads (the live hull's
  // latency); the mesh is identical for any value (same vertices, triangles and order).
  int threads = 1;
};

// Cost follows the occupied part of the grid (the bounding rectangle of the non-empty columns).
// Keeps its working memory per thread between calls, so a frame loop does not reallocate it.
Mesh segment_marching_cubes(const SegmentSet& set, const MeshOptions& options = {});

// (Re)computes mesh.normals: unit area-weighted vertex normals (zero for isolated vertices).
void compute_normals(Mesh& mesh);

// Topology report for tests and tools.
struct MeshTopology {
  std::size_t edges = 0;
  std::size_t boundary_edges = 0;       // used by one triangle
  std::size_t non_manifold_edges = 0;   // used by more than two
  std::size_t inconsistent_edges = 0;   // two triangles traversing the edge the same way
  std::size_t degenerate_triangles = 0; // repeated vertex index
  bool watertight() const { return boundary_edges == 0 && non_manifold_edges == 0; }
  bool oriented() const { return inconsistent_edges == 0; }
};
MeshTopology check_topology(const Mesh& mesh);

}  // namespace studio::hull
