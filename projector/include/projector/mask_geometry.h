#pragma once
// The grown actor mask as geometry a renderer draws (TCSVT 2004 §V-D: the actor mesh rendered
// black from the projector's viewpoint with no depth test, enlarged by the security margin).
// Growing by the margin, in two forms (GrowOptions::projector chooses; the projector node's
// mask_growth, default outline), and a radius:
// - grow_mesh(): every vertex pushed out along its area-weighted normal by margin / c, where c is
//   the smallest cosine between the vertex normal and the normals of its triangles (clamped at
//   min_cosine), so every triangle's plane moves out by at least the margin, also at the box-like
//   edges and corners a hull mesh has. A mesh of more than GrowOptions::max_triangles is first
//   simplified to that many (the simplifier's error, x error_safety, added to the push), so a
//   dense hull mesh does not become thousands of margin-sized triangles drawn over one another.
//   Draw it like the mesh (no depth test, black, both faces). Self-overlaps in concave places are
//   harmless: the mask is a union.
// - grow_outline() (below): the mesh's image in one projector grown by the margin ball's
//   projected radius, drawn as quads; covers the margin, not the push's spikes (about half the
//   black at the demo's margins: BENCHMARKS.md, demo, session 14).

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/camera.h"
#include "core/error.h"
#include "projector/actor_mesh.h"

namespace studio::projector {

struct GrowOptions {
  double min_cosine = 0.3;  // limits the push at needle-sharp vertices to margin / 0.3
  // A mesh of more triangles is simplified to this many first (0: never); its surface error
  // (the simplifier's, times error_safety) is added to the margin. max_error bounds that error,
  // relative to the mesh's extent (0.01 of a 2 m actor: 2 cm).
  std::size_t max_triangles = 3000;
  double max_error = 0.01;
  double error_safety = 1.5;
  // A mesh of more than cluster_factor x max_triangles is first clustered to about that many by
  // meshoptimizer's sloppy simplifier (vertex clustering on a grid: the vertices kept are
  // original ones), then edge-collapsed to max_triangles; both stages' errors add up (x
  // error_safety) in the push. On the demo's hull meshes (89k triangles, 25 frames), clustered
  // to 4 x: 7.9 instead of 32.6 ms CPU per mesh, error 2.6 instead of 1.7 cm, and silhouettes
  // from 6 views at a 1 cm margin left 0 pixels of the mesh uncovered (the edge collapse alone:
  // 15 of 4.4 M). false: the edge collapse alone on the whole mesh.
  bool presimplify = true;
  // The clustering's target, x max_triangles (>= 1; 1: the edge collapse runs only when the
  // clustering stopped above max_triangles). 2 was measured and not taken: 3.6 instead of 4.9 ms
  // CPU per hull mesh (projector_mask_bench BM_SimplifyHull), but a fatter mask on the
  // tessellated swing (test TwoStageSimplification...: 178-226 points 5 cm out inside it, not
  // 148-152).
  std::size_t cluster_factor = 4;
  // The projector the mask is drawn by: grow_mask() then grows the mask in that projector's
  // image (grow_outline below) instead of pushing the vertices out. None: the vertex push.
  std::optional<Camera> projector;
  // With `projector` (the outline form), simplify_for_mask() keeps the mesh whole unless this is
  // set: the outline's raster is linear in the triangles and cheap per triangle, the
  // simplification is not, and a whole mesh adds no simplifier error to the margin. The demo's
  // hull mesh (29k triangles, projector_bench HullMask_720p, 0.2 m, same run): 12.8 ms CPU per
  // frame to grow and draw it whole against 10.4 simplified to 3000 + 6.8 per mesh to simplify
  // (projector_mask_bench SimplifyHull), and 197k black pixels against 223k (BENCHMARKS.md,
  // demo, session 15). The vertex push still simplifies (grow_mask() does it when the outline
  // falls back on a whole mesh).
  bool simplify_outline = false;
  // The outline form's bound: a mesh of more triangles (a hull far finer than the demo's 160
  // columns) is clustered to about this many first (meshoptimizer's sloppy simplifier, its error
  // x error_safety added to the margin), so the per-frame raster stays bounded (0: no bound).
  std::size_t outline_max_triangles = 100000;
};

// Errors: invalid mesh, negative or non-finite margin. = grow_mask(simplify_for_mask(mesh)).
Expected<ActorMesh> grow_mesh(const ActorMesh& mesh, double margin_m,
                              const GrowOptions& options = {});

// The two halves of grow_mesh(), so a caller that grows one mesh for many frames (the projector:
// a mesh per 40 ms, frames in between, each predicted to its own display instant) simplifies it
// once. MaskBase::mesh holds at most max_triangles triangles (every triangle in the outline form
// unless simplify_outline) and only the vertices they use
// (input vertices, not moved; source[i] is vertex i's index in the input, so a motion estimated
// per input vertex applies: velocities_at()); error_m is how far its surface may lie from the
// input's (the simplifier's error x error_safety), which grow_mask() adds to the margin.
struct MaskBase {
  ActorMesh mesh;
  double error_m = 0;
  std::vector<uint32_t> source;  // per vertex of mesh: its index in the input mesh
};
// Errors: invalid mesh or options.
Expected<MaskBase> simplify_for_mask(const ActorMesh& mesh, const GrowOptions& options = {});
// Every vertex pushed out by (margin + base.error_m) / c (see above), or with
// GrowOptions::projector the outline form (falling back to the push where it cannot be made); no
// further simplification. Errors: invalid mesh, negative or non-finite margin, invalid options.
Expected<ActorMesh> grow_mask(const MaskBase& base, double margin_m,
                              const GrowOptions& options = {});

// The outline form (GrowOptions::projector): what a projector must black out is the projection
// of the mesh grown by the margin m in every direction (its Minkowski sum with a ball), and a
// ball of radius m at distance d from the projector's centre is seen within the angle
// a = asin(m / d) of its centre's ray. So the mask is made in the projector's image (its
// distortion-free pinhole, as the renderer draws it), on a grid of square cells of about a tenth
// of the radius (2..4 px; `cell` the smallest) over the mesh's image grown by the radius
// (clipped to the image and that radius round it):
//   1. conservative raster: a cell is set when any triangle's projection overlaps it;
//   2. exact Euclidean distance transform (Felzenszwalb & Huttenlocher) of the set cells;
//   3. a cell joins the mask when the distance between its centre and a set cell's is at most
//      rho + sqrt(2) cell, rho = f_max tan(a_max) / cos^2(theta + 2 a_max): f_max the larger
//      focal length, a_max the angle for the nearest vertex, theta the cell's angle from the
//      optical axis (a pinhole stretches angles by up to 1 / cos^2 there);
//   4. the mask cells become quads (0.5 px wider each side), placed 1 m in front of the
//      projector on the rays of their corners, so drawn from the projector they cover exactly
//      those pixels: in bands of about `band_px` pixel rows, the columns every row of the band
//      covers as one tall quad and each row's rest as its own (0: every row's runs alone); the
//      quads overlap at most along 1-px seams. The pixels they cover, as rectangles, are
//      ActorMesh::image_rects: FrameRenderer clears those instead of rasterising the quads
//      (quads 2-4 px tall put every 4 x 4 block they touch on llvmpipe's slow path; bands
//      halve their number). The same pixels either way (projector_bench SceneImageFrame_720p).
// Every pixel within rho of the mesh's projection is covered, so the actor grown by the margin
// is; the black reaches at most rho + ~2 cells beyond the outline where the vertex push reaches
// margin / cosine along averaged normals (up to 3.3 x the margin: spikes). Errors: invalid
// mesh or margin, a vertex closer to the projector's centre than the margin or behind its near
// plane (5 cm), a projector without a valid size or focal lengths; grow_mask() then falls back to
// the vertex push, which has none of these limits.
Expected<ActorMesh> grow_outline(const ActorMesh& mesh, double margin_m, const Camera& projector,
                                 int cell = 2, int band_px = 16);

}  // namespace studio::projector
