#pragma once
// Photo-consistent refinement of the visual hull (TCSVT 2004 §IV-B names it for the offline
// phase: "voxel colouring or shape carving"). The visual hull cannot see concavities (between
// an arm and the body, under a crouching actor's chest); the colour images can: a point of the
// hull that is not on the actor's surface is seen by different cameras as different surface
// points, so their colours disagree.
//
// Method: generalised voxel colouring (Culbertson, Malzbender, Slabaugh, "Generalized Voxel
// Coloring", 1999; Kutulakos & Seitz, "A Theory of Shape by Space Carving", IJCV 2000) on the
// hull's own grid. The segment set is sampled into cubic voxels (edge = the column spacing), and
// repeatedly:
//   1. every camera's depth buffer of the current surface voxels gives visibility (a voxel is
//      seen by camera c iff it is in front of c, faces it (n.v >= min_cos) and no surface voxel
//      lies more than `depth_tolerance` cells nearer on its pixel);
//   2. each surface voxel seen by >= min_cameras cameras gathers their colours at its
//      projection — never from a pixel within `edge_margin_px` of that camera's silhouette
//      boundary (the blue spill and the anti-aliased edge mix the cloth into the actor there)
//      and with weights cos^2 (grazing views carry the most spill);
//   3. a voxel whose weighted colour spread (RMS over cameras, blue channel half weight: the
//      spill and the blue LED ring tint mostly blue) exceeds `threshold` is carved;
//   4. a voxel the colours leave undecided is also carved when luminance patches on its tangent
//      plane disagree between the seeing cameras (mean NCC < ncc_threshold) and a point 1..3
//      cells deeper along the normal agrees clearly better (shading gradients: a phantom voxel
//      in front of uniformly coloured cloth sees different surfaces in different cameras);
// until nothing changes. Carving never goes deeper than `max_depth_cells` below the hull (a
// bound on what a wrong colour can do) and never removes a voxel seen by fewer than
// min_cameras cameras (no evidence: the hull stays).
//
// The result is a SegmentSet over the same grid: hull intervals without a carved voxel are
// returned exactly (so an uncarved region's mesh is the hull's mesh), carved ends lie on voxel
// faces.

#include <cstddef>
#include <span>

#include "core/camera.h"
#include "core/error.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "hull/segment_mesh.h"
#include "hull/segment_set.h"

namespace studio::offline {

// One camera of a frame: its calibration, colour image and keyed silhouette (same size).
struct ColourView {
  const Camera* camera = nullptr;
  ImageView<const Rgb8> image;
  const RunMask* mask = nullptr;
};

struct CarveOptions {
  double threshold = 6.0;        // carve above this weighted RGB spread (grey levels, RMS)
  int min_cameras = 2;           // consistency needs at least this many views of a voxel
  // At most this many of the seeing cameras judge a voxel, the most frontal ones (0: all). More
  // judges see the voxel from wider angles, where the ring lights' tint and the spill differ
  // from camera to camera: on a 17-camera rig (8 ring + overhead + 8 low) all judges carved
  // the true surface (carved + surface stage +11.6 % / +15.0 % mean / p95 against the hull on
  // the train poses), 3 gives -4.0 % / -7.9 % (validation -6.0 / -13.3 against -1.1 / -5.9);
  // on the 9-camera rig, where a voxel rarely has more than 3 judges, within 0.4 points of all
  // (offline_surface_sweep, BENCHMARKS.md, offline, session 15). 2 loses 2-3 points there.
  int max_judges = 3;
  double min_cos = 0.5;          // views more grazing than this do not judge a voxel (spill)
  int edge_margin_px = 2;        // silhouette border pixels not used (blue spill)
  int sample_radius_px = 0;      // colour = mean over a (2r+1)^2 pixel patch (noise)
  double depth_tolerance = 1.5;  // cells: visibility slack of the depth buffers
  int max_depth_cells = 12;      // carving stops this many cells below the hull surface
  int max_iterations = 60;
  // Shading structure (patches): a voxel is also carved when the zero-mean NCC of luminance
  // patches on its tangent plane, averaged over the pairs of seeing cameras whose patches have
  // structure (std >= patch_min_std), is below ncc_threshold while its colour spread exceeds
  // ncc_min_spread. A phantom voxel in front of a uniformly coloured concavity sees different
  // shading gradients in different cameras; on the true surface they agree. patch_half = 0: off.
  int patch_half = 3;                // (2h+1)^2 samples
  double patch_spacing_cells = 0.5;  // sample spacing on the tangent plane
  double patch_min_std = 2.0;        // grey levels
  double ncc_threshold = 0.0;
  double ncc_min_spread = 2.0;
  double ncc_gain = 0.3;  // ... and a point 1..3 cells deeper matches better by this much
  int threads = 1;        // surface voxels are judged in parallel
  // Judge again, after the first iteration, only the surface voxels whose verdict could change:
  // new on the surface, a voxel within 2 cells carved (their normal), or a depth-buffer pixel
  // they consult changed (every camera undistorted; else all are judged). The same result as
  // judging all of them (PhotoCarve.IncrementalJudgingCarvesTheSameVoxels), several times faster.
  bool incremental = true;
  Expected<void> validate() const;
};

struct CarveResult {
  hull::SegmentSet set;  // the refined shape (a subset of the hull)
  int iterations = 0;
  std::size_t voxels = 0;  // hull voxels sampled
  std::size_t carved = 0;  // voxels removed
  std::size_t judged = 0;  // surface voxels judged, over all iterations
};

// Fails (one line) on invalid options, no views, or a view whose image or mask size differs
// from its camera. The result does not depend on options.threads.
Expected<CarveResult> photo_carve(const hull::SegmentSet& hull, std::span<const ColourView> views,
                                  const CarveOptions& options = {});

// The refined mesh: segment marching cubes of `refined`, with the exact silhouette crossings
// (hull/crossing_refine.h) wherever the surface is still the hull's; where it was carved the
// crossing stays at half a cell (the silhouettes say nothing there).
Expected<hull::Mesh> refined_mesh(const hull::SegmentSet& refined, const hull::SegmentSet& hull,
                                  std::span<const ColourView> views, int threads = 1);

}  // namespace studio::offline
