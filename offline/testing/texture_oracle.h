#pragma once
// Texture measurements against the simulated studio's truth (tests and benchmarks only; never in
// the product): the held-out view's error split into what the geometry costs and what the
// texturing costs. The same blend (offline/texture.h) is rendered
//  - per vertex on the reconstructed mesh (the product's glb: COLOR_0 interpolated),
//  - per sub-pixel on the reconstructed mesh (the blend evaluated at every rendered surface
//    point: what an atlas of unlimited resolution would show), and
//  - per sub-pixel on the TRUE surface with true visibility (the oracle: the blend's own error,
//    with no geometry error at all),
// each anti-aliased over the held-out camera's clean plate and scored over the actor's interior,
// its border band and the pixels the render covers outside the true silhouette.

#include <cstddef>
#include <vector>

#include "core/camera.h"
#include "core/image.h"
#include "hull/segment_mesh.h"
#include "offline/texture.h"
#include "sim/actor.h"

namespace studio::offline::testing {

// The actor's true surface as one mesh: every part tessellated (`segments` around), normals
// exact. Parts interpenetrate, so the mesh is not the union's boundary, but its z-buffer from any
// camera is the union's (what visibility needs).
hull::Mesh true_mesh(const sim::ActorBody& body, int segments = 96);

// What one sub-pixel sees: a surface point and its outward unit normal.
struct SurfaceSample {
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), n = Eigen::Vector3d::Zero();
  bool hit = false;
};
// The sub-pixels (ss x ss per pixel; sub-pixel (i, j) of pixel (x, y) at x + (i + 0.5) / ss -
// 0.5, row-major over the fine image of width * ss columns) of `camera`:
// the true surface by ray casting,
std::vector<SurfaceSample> truth_surface(const sim::ActorBody& body, const Camera& camera, int ss);
// a mesh by z-buffered rasterisation, position and normal interpolated perspective-correctly.
std::vector<SurfaceSample> mesh_surface(const hull::Mesh& mesh, const Camera& camera, int ss);

// The blend evaluated at every hit sub-pixel, box-filtered over `plate`. Hit sub-pixels no camera
// sees take the mean of their seen 4-neighbours, repeated (as the per-vertex fill); `unseen`
// counts them. `coverage`: pixels any sub-pixel hits.
Image<Rgb8> blend_over(const std::vector<SurfaceSample>& surface, const Camera& camera, int ss,
                       const TextureBlend& blend, const Image<Rgb8>& plate, Mask* coverage,
                       std::size_t* unseen = nullptr);

// A held-out render against the camera's true image: PSNR over the interior (true mask without
// its 2-px border), over the union of the true mask and the render's coverage (the issue's
// measure), and where the union's squared error is (interior, border band, covered outside the
// true mask), with the pixel counts.
struct HeldOutScore {
  double interior_db = 0, union_db = 0;
  double share_interior = 0, share_border = 0, share_outside = 0;
  std::size_t interior_px = 0, border_px = 0, outside_px = 0;
  std::size_t uncovered_px = 0;  // interior pixels the render does not cover
};
HeldOutScore score_held_out(const Image<Rgb8>& render, const Mask& coverage,
                            const Image<Rgb8>& truth, const Mask& true_mask);

}  // namespace studio::offline::testing
