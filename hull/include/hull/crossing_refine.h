#pragma once
// Exact horizontal crossings for the segment mesh (extends TCSVT 2004 §IV-C).
//
// Segment marching cubes places every vertex that lies between an inside column and an outside
// column at half a cell (marching squares on binary corners). Along the continuous axis the mesh
// is exact, but across the columns the half-cell guess biases every silhouette outwards: the
// extremal column of a cross-section is inside, and the contour is put half a cell beyond it, so
// the mesh re-projects about half a cell too wide in every camera (IoU ~0.93 at 128x128 columns
// in the simulated studio).
//
// refine_crossings() moves each such vertex along its grid edge to where that edge leaves the
// visual hull: the horizontal segment from the inside column to the outside column, at the
// vertex's height, is cut by every silhouette exactly like a column (PreparedView::cut_line);
// the vertex goes to the end of the surviving piece that starts at the inside column. At a
// height where one of the two columns starts or ends, the crossing is taken just beside it on
// the side where exactly one column is inside. Only vertex positions change (clamped strictly
// between the two columns), so the mesh keeps its topology: still watertight and consistently
// oriented. Normals are recomputed. Vertices on columns and cell centres do not move.
// Cost: one short line cut per crossing vertex and camera, except for a distortion-free camera in
// which the line's image lies, in every pixel row it crosses, within one run of that row (it
// would keep the line whole): at the demo's 160x160 columns with 6 cameras only 16 k of 73 k
// vertex-camera pairs per frame are cut (BENCHMARKS.md, "The live hull's frame").

#include <span>

#include "core/error.h"
#include "hull/segment_mesh.h"
#include "hull/segment_set.h"
#include "hull/silhouette_cut.h"

namespace studio::hull {

// `mesh` must come from segment_marching_cubes(set); `views` are the silhouettes that cut `set`.
// Fails (mesh untouched) on a mask whose size differs from its camera. Vertices are independent:
// options.threads workers share them (the result does not depend on the thread count).
// `normals`: the vertex normals recomputed for the moved vertices; false: mesh.normals cleared
// (a caller that does not publish them).
Expected<void> refine_crossings(Mesh& mesh, const SegmentSet& set, std::span<const View> views,
                                const CutOptions& options = {}, bool normals = true);

}  // namespace studio::hull
