#pragma once
// Live-like actor meshes for the projector's benches: what the hull service publishes in the demo
// (true masks of the simulated ring's 6 cameras at 704x576 -> silhouette cut at 160 x 160 columns
// over 3 x 2.4 x 3 m -> segment marching cubes -> exact crossings), 25 Hz, `motion` of the
// simulated actor. Consecutive meshes share no vertices, as in the live studio. The demo's live
// meshes are 35-51k triangles; the arm swing's are ~35-40k here.
// Header-only: the benches that include it link studio_hull and studio_sim.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "projector/actor_mesh.h"
#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::projector::testing {

// `frames` meshes from studio frame `first` on (40 ms apart), hull grid `columns` per side.
inline std::vector<ActorMesh> hull_meshes(sim::Motion motion, int first, int frames,
                                          int columns = 160) {
  sim::StudioOptions so;
  so.actor.motion = motion;
  so.noise_sigma = 0;  // only the true masks are used
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
  if (!studio) throw std::runtime_error(studio.error().message);
  hull::GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = hull::Axis::y;
  g.cells_u = g.cells_v = columns;
  hull::CutOptions cut;
  const std::size_t n = std::size_t(studio->camera_count());
  const int64_t frame_ns = int64_t(1e9 / studio->options().fps + 0.5);
  std::vector<ActorMesh> out;
  for (int f = first; f < first + frames; ++f) {
    std::vector<Mask> truth(n);
    std::vector<RunMask> runs(n);
    std::vector<hull::View> views;
    for (std::size_t c = 0; c < n; ++c) {
      studio->render(int(c), f, nullptr, &truth[c]);
      runs[c] = RunMask::from_mask(truth[c].view());
    }
    for (std::size_t c = 0; c < n; ++c) views.push_back({&studio->cameras()[c], &runs[c]});
    auto set = hull::visual_hull(g, views, cut);
    if (!set) throw std::runtime_error(set.error().message);
    hull::Mesh mesh = hull::segment_marching_cubes(*set);
    if (auto ok = hull::refine_crossings(mesh, *set, views, cut); !ok)
      throw std::runtime_error(ok.error().message);
    if (mesh.empty()) throw std::runtime_error("hull_meshes: frame " + std::to_string(f) + " empty");
    ActorMesh a;
    a.vertices = std::move(mesh.vertices);
    a.triangles = std::move(mesh.triangles);
    a.capture_ns = 1'000'000'000 + int64_t(f) * frame_ns;
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace studio::projector::testing
