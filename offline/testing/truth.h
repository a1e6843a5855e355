#pragma once
// Scoring against the simulated studio's truth (tests and benchmarks only): surface distance of
// a mesh to the true actor, a simulated frame with colour images and keyed masks, and a CPU
// renderer of a vertex-coloured mesh for PSNR against a held-out camera's true image.

#include <string>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "core/run_mask.h"
#include "hull/segment_mesh.h"
#include "hull/segment_set.h"
#include "offline/photo_carve.h"
#include "sim/actor.h"
#include "sim/studio.h"

namespace studio::offline::testing {

// Distances (metres) between a mesh and the true surface, from dense area-uniform samples of
// both: `accuracy` from the mesh to the truth, `completeness` from the truth to the mesh, and
// both pooled (`both`).
struct Distances {
  double mean = 0, p95 = 0;
};
struct SurfaceScore {
  Distances accuracy, completeness, both;
};
SurfaceScore surface_distance(const hull::Mesh& mesh, const sim::ActorBody& truth,
                              int samples = 300000);

// Where a mesh's error is (issue 21: concavities the hull cannot see, or the surface near the
// silhouettes): the pooled distances (mesh -> truth and truth -> mesh) split by the body region of
// the nearest true surface point (torso = pelvis, torso, shoulders; arms = upper and lower arms,
// hands; legs = legs, feet; head = neck, head, hair) and by size (within one `cell` of the truth:
// surface placement; beyond: volume the mesh has in excess or misses). `share` = the bucket's
// sum of distances over the sum of all distances (so the shares add up to 1 and say where the
// mean comes from); `p95_share` = the bucket's share of the samples beyond the pooled p95.
struct ErrorBucket {
  std::string region;
  bool far = false;  // beyond one cell
  double samples = 0, share = 0, p95_share = 0;
};
std::vector<ErrorBucket> error_breakdown(const hull::Mesh& mesh, const sim::ActorBody& truth,
                                         double cell, int samples = 200000);

// Distance of each point to the true surface (nearest of dense surface samples).
std::vector<double> distances_to_truth(const std::vector<Eigen::Vector3d>& points,
                                       const sim::ActorBody& truth, int samples = 300000);

// Mesh samples farther than `distance` from the true surface (where the excess is).
std::vector<Eigen::Vector3d> far_mesh_points(const hull::Mesh& mesh, const sim::ActorBody& truth,
                                             double distance, int samples = 100000);

// One frame of a simulated studio: colour images, keyed masks (the keyer's blue defaults) and the
// truth.
struct Frame {
  std::vector<Camera> cameras;
  std::vector<Image<Rgb8>> images;
  std::vector<RunMask> masks;
  sim::FrameTruth truth;
  std::vector<ColourView> views() const;
};
Frame render_frame(const sim::SimulatedStudio& studio, int64_t frame);

// Renders a mesh with per-vertex display colours (0..255) from `camera`: z-buffered, colours
// interpolated; pixels nothing covers keep `background`.
Image<Rgb8> render_coloured(const hull::Mesh& mesh, const std::vector<Eigen::Vector3f>& colours,
                            const Camera& camera, Rgb8 background = {0, 0, 0});

// The same, anti-aliased (ss x ss sub-pixels per pixel, box filter) and composited over `plate`
// (the camera's view of the empty studio): what a compositor makes of the textured actor, so
// that the silhouette's border pixels (cloth and actor mixed in the camera's image) compare like
// for like. `coverage`: pixels any sub-pixel of the mesh covers.
Image<Rgb8> render_over(const hull::Mesh& mesh, const std::vector<Eigen::Vector3f>& colours,
                        const Camera& camera, const Image<Rgb8>& plate, int ss = 4,
                        Mask* coverage = nullptr);

// PSNR (dB) of `image` against `truth` over the pixels of `region` (non-zero).
double psnr(const Image<Rgb8>& image, const Image<Rgb8>& truth, const Mask& region);

// The mask eroded by a (2r+1)^2 square (the actor without its r-pixel border).
Mask erode(const Mask& mask, int r);

// The hull's grid over the simulated acting area.
hull::GridSpec studio_grid(int n);

}  // namespace studio::offline::testing
