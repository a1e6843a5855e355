#pragma once
// Surface refinement after carving (issue 21, goal 1): two terms on the carved mesh's vertices.
//
// A. The photo term (options.iterations, default 0 = off; measured to give no gain on the
//    simulated studio, docs/offline.md): each vertex moves along its (ring-averaged) normal to the
//    depth where the cameras that see it agree best, with a smoothness term, sub-cell precision,
//    and no move where fewer than min_cameras cameras see it. Per iteration:
//   1. every camera's z-buffer of the current mesh; camera c sees vertex x iff x is in front of
//      c, cos(n, to c) >= min_cos (grazing views carry the most blue spill), x is not hidden, and
//      the patch lies in c's silhouette interior, edge_margin_px from its border (view_sampling.h);
//   2. the score S(d) of the offsets d in [-search_in, +search_out] cells: luminance patches on
//      the tangent plane at x + d n in the seeing cameras (the same cameras, and for NCC the same
//      pairs, at every d), compared pairwise: minus the RMS difference (ssd) or the mean zero-mean
//      NCC (Furukawa & Ponce, PAMI 2010, eq. 1, sampled on a line along the normal as in
//      Vogiatzis et al., PAMI 2007); the best d, refined by a parabola, is evidence when it is a
//      peak inside the range, good enough (max_rms / min_ncc) and better than d = 0 by min_gain;
//   3. offsets: min sum_i w_i (delta_i - t_i)^2 + prior sum_i delta_i^2
//                   + smoothness sum_(i,j) edges (delta_i - delta_j)^2   (Jacobi steps);
//   4. x += delta n, the total bounded to [-max_in, +max_out] cells.
// B. The shape prior (shape_steps, default 10): Laplacian steps x += lambda (mean of neighbours
//    - x) with the rim vertices anchored (on a camera's silhouette contour, seen grazing by it:
//    where the visual hull touches the true surface), each move kept inside the visual hull
//    (inside_hull). The hull's facets bulge outwards between
//    the silhouette cones that bound them; the true surface is smooth and inside: the steps move
//    the bulges inwards and leave the contour generators in place.
// The result is independent of `threads` (every step is per vertex from the previous state).

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "core/error.h"
#include "hull/segment_mesh.h"
#include "offline/photo_carve.h"

namespace studio::offline {

// Photo-consistency of a depth: the mean zero-mean NCC of the patch pairs, or minus the RMS
// difference of their luminance (SSD: not invariant to a shift of a shading ramp, which is all a
// uniformly coloured limb offers between two views).
enum class PhotoMeasure { ssd, ncc };

struct SurfaceRefineOptions {
  PhotoMeasure measure = PhotoMeasure::ssd;
  double cell = 0;                // metres: the grid's cell (all *_cells below are in cells)
  double search_in_cells = 1.5;   // per iteration, inward
  double search_out_cells = 1.0;  // per iteration, outward
  double step_cells = 0.25;       // depth samples along the normal (then a parabola)
  double max_in_cells = 6.0;      // total displacement bounds
  double max_out_cells = 1.0;
  int patch_half = 3;  // (2h+1)^2 samples per patch
  double patch_spacing_cells = 0.5;
  double patch_min_std = 2.0;  // grey levels: flatter patches carry no evidence
  double min_cos = 0.5;        // grazing views (the most spill) do not judge
  int edge_margin_px = 2;
  double depth_tolerance_cells = 2.0;  // visibility slack of the mesh's z-buffers
  int normal_rings = 3;                // normals averaged over this many rings of neighbours
  int min_cameras = 2;
  double min_ncc = 0.5;      // ncc: the best depth's score must reach this
  double max_rms = 8.0;      // ssd: the best depth's RMS difference (grey levels) must stay below
  bool require_peak = true;  // the best depth is inside the searched range (not a slope's end)
  double min_gain = 1.0;     // and beat the current position by this (score units: grey levels)
  double smoothness = 1.0;
  double prior = 1.0;
  int iterations = 0;  // photo-term iterations: off by default (measured: no gain, docs)
  int smooth_steps = 40;
  // The shape prior: Laplacian steps after the photo term, rim vertices anchored.
  int shape_steps = 10;
  double shape_lambda = 0.5;
  bool anchor_rims = true;
  double rim_cos = 0.08;  // a rim vertex: |cos(normal, view)| below this, on the contour (1 px)
  // > 0: of a camera's facet (the hull's surface on the cone of one contour pixel: every vertex
  // there passes the rim test), only the vertices within rim_band_cells of the middle of its
  // extent along the pixel's ray stay anchored. The true surface touches the cone somewhere on
  // the strip, the facet lies outside it elsewhere (a convex cross-section seen by cameras 45
  // degrees apart is circumscribed by a polygon touching it near each side's middle); the rest
  // of the facet is free to move in. 0: every facet vertex is anchored (sessions 8-9). Measured
  // (docs/offline.md, session 10): -18.9 / -23.6 % -> -20.8 / -26.1 % mean / p95 vs the hull on
  // the train pair with 10 steps.
  double rim_band_cells = 1;
  // Each step's move is kept inside the visual hull: a vertex whose projection is inside a
  // camera's silhouette (nearest pixel) stays inside it (the move is halved up to 3 times, else
  // the vertex stays). Laplacian steps move concave creases outwards (the hull's fold between an
  // arm and the torso); the true surface is inside the hull everywhere, so those moves only add
  // excess. Measured on 7 simulated poses: -0.6 points of mean distance (docs/offline.md).
  bool inside_hull = true;
  // 1: Laplacian steps (membrane, x += lambda U(x)); 2: bi-Laplacian steps (thin plate,
  // x -= lambda U(U(x)), lambda <= 0.25). U(x) = mean of the neighbours - x. Measured: 2 is worse
  // than 1 on every tested pose (docs/offline.md).
  int shape_order = 1;
  int threads = 1;
  Expected<void> validate() const;
};

struct SurfaceRefineResult {
  hull::Mesh mesh;
  int iterations = 0;
  std::size_t evidence = 0;  // vertices with a data term in the last iteration
  std::size_t unseen = 0;    // vertices fewer than min_cameras cameras see (last iteration)
  std::size_t anchored = 0;  // rim vertices the shape prior kept in place
  double mean_shift = 0;     // metres, mean distance moved over all vertices
  // The first iteration's data term per input vertex (diagnostics: metres along `directions`;
  // weight 0 = no evidence).
  std::vector<float> first_target, first_weight;
  std::vector<Eigen::Vector3f> directions;
};

// Fails (one line) on invalid options, no views, or views whose sizes differ from their cameras.
Expected<SurfaceRefineResult> refine_surface(const hull::Mesh& mesh,
                                             std::span<const ColourView> views,
                                             const SurfaceRefineOptions& options);

}  // namespace studio::offline
