// Photo-consistent refinement against the simulated studio's truth (issue 21, "done when"): on
// concave poses (standing with the arms close to the body; crouching) the refined surface is
// closer to the true actor than the visual hull at the same resolution.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/photo_carve.h"
#include "offline/texture.h"
#include "sim/cameras.h"
#include "testing/truth.h"

namespace studio::offline {
namespace {

std::vector<Camera> rig() {
  sim::RingOptions ring;
  ring.count = 9;  // 8 on the ring + overhead
  std::vector<Camera> cams = sim::ring_cameras(ring);
  // The held-out camera (last): between two ring cameras, a little lower; feeds nothing.
  sim::RingOptions held = ring;
  held.count = 8;
  held.overhead = false;
  held.first_azimuth_deg = 22.5;
  held.height_m = 1.7;
  Camera h = sim::ring_cameras(held).front();
  h.id = "held_out";
  cams.push_back(h);
  return cams;
}

struct Scores {
  testing::SurfaceScore hull, refined;
};

Scores score(const sim::SimulatedStudio& studio, int64_t frame, int grid, const CarveOptions& o) {
  const testing::Frame f = testing::render_frame(studio, frame);
  auto views = f.views();
  views.pop_back();  // the held-out camera
  std::vector<hull::View> cut_views;
  for (const auto& v : views) cut_views.push_back({v.camera, v.mask});
  const hull::SegmentSet set = hull::visual_hull(testing::studio_grid(grid), cut_views).value();
  hull::Mesh hull_mesh = hull::segment_marching_cubes(set);
  EXPECT_TRUE(hull::refine_crossings(hull_mesh, set, cut_views).has_value());
  const CarveResult carved = photo_carve(set, views, o).value();
  const hull::Mesh mesh = refined_mesh(carved.set, set, views).value();
  Scores s{testing::surface_distance(hull_mesh, f.truth.body),
           testing::surface_distance(mesh, f.truth.body)};
  std::printf("frame %lld grid %d: carved %zu of %zu voxels in %d iterations\n", (long long)frame,
              grid, carved.carved, carved.voxels, carved.iterations);
  const auto row = [](const char* what, const testing::SurfaceScore& s) {
    std::printf("  %-8s mean/p95 mm: accuracy %.2f/%.2f completeness %.2f/%.2f both %.2f/%.2f\n",
                what, 1e3 * s.accuracy.mean, 1e3 * s.accuracy.p95, 1e3 * s.completeness.mean,
                1e3 * s.completeness.p95, 1e3 * s.both.mean, 1e3 * s.both.p95);
  };
  row("hull", s.hull);
  row("refined", s.refined);
  for (const hull::Mesh* m : std::vector<const hull::Mesh*>{&hull_mesh, &mesh}) {
    TextureOptions to;
    to.threads = 2;
    const auto colours = vertex_colours(*m, views, to).value();
    const Image<Rgb8> rendered = testing::render_coloured(*m, colours, f.cameras.back());
    Mask truth_mask;
    studio.render(int(f.cameras.size()) - 1, frame, nullptr, &truth_mask);
    std::printf("  psnr %s: %.2f dB (eroded %.2f)\n", m == &mesh ? "refined" : "hull",
                testing::psnr(rendered, f.images.back(), truth_mask),
                testing::psnr(rendered, f.images.back(), testing::erode(truth_mask, 2)));
  }
  return s;
}

TEST(PhotoCarve, ExperimentPoses) {
  CarveOptions o;
  o.threads = 2;
  if (const char* e = std::getenv("CARVE_T")) o.threshold = std::atof(e);
  if (const char* e = std::getenv("CARVE_COS")) o.min_cos = std::atof(e);
  if (const char* e = std::getenv("CARVE_DEPTH")) o.max_depth_cells = std::atoi(e);
  for (sim::Motion m : {sim::Motion::idle, sim::Motion::crouch}) {
    sim::StudioOptions so;
    so.actor.motion = m;
    auto studio = sim::SimulatedStudio::create(rig(), so).value();
    const int64_t frame = m == sim::Motion::crouch ? 45 : 10;
    score(studio, frame, 256, o);
  }
}

}  // namespace
}  // namespace studio::offline
