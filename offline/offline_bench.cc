// The offline post-production frame (issue 21) on the simulated studio: 9 cameras (8 ring +
// overhead) at 704x576, the actor crouching (frame 45), one core per frame (the CLI runs frames in
// parallel, one per core). Stages after keying: hull = cut + segment marching cubes + exact
// crossings (the baseline: `studio-hull offline` without --refine); carve = photo_carve;
// refined_mesh; surface = refine_surface (default options: the shape prior); texture =
// vertex_colours; encode = the glb bytes; balance = the colour balance before the carve (the
// CLI's default: its own hull at 128 columns, estimate_colour_balance, apply_colour_balance).
// BM_Frame runs a whole frame per mode at 256^2 and 512^2 columns (frames_per_min_1core: one core,
// the thread CPU time of the stages). BM_Quality: the refinement's quality (surface distance to the
// true actor, counters in mm) against its cost, per threshold and surface setting, with the hull as
// the baseline in the same run.
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "offline/colour_balance.h"
#include "offline/frame_files.h"
#include "offline/photo_carve.h"
#include "offline/surface_refine.h"
#include "offline/texture.h"
#include "sim/cameras.h"
#include "testing/truth.h"

namespace studio::offline {
namespace {

struct Scene {
  testing::Frame frame;
  std::vector<ColourView> views;
  std::vector<hull::View> cut_views;
  Scene() {
    sim::RingOptions ring;
    ring.count = 9;
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::crouch;
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(ring), so).value();
    frame = testing::render_frame(studio, 45);
    views = frame.views();
    for (const auto& v : views) cut_views.push_back({v.camera, v.mask});
  }
  static const Scene& get() {
    static const Scene s;
    return s;
  }
};

hull::Mesh hull_mesh(const Scene& s, const hull::SegmentSet& set) {
  hull::Mesh m = hull::segment_marching_cubes(set);
  (void)hull::refine_crossings(m, set, s.cut_views);
  return m;
}

// The calling thread's CPU time.
struct ThreadClock {
  using duration = std::chrono::nanoseconds;
  using time_point = std::chrono::time_point<ThreadClock>;
  static time_point now() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return time_point(duration(int64_t(t.tv_sec) * 1000000000 + t.tv_nsec));
  }
};

// range(0): grid; range(1): 0 hull only, 1 refined, 2 refined + textured, 3 refined + surface,
// 4 refined + surface + textured, 5 refined + surface without the hull constraint (its cost, the
// baseline in the same run), 6 refined + surface with every facet vertex anchored
// (rim_band_cells 0, sessions 8-9: the baseline of the facet-middle anchors).
void BM_Frame(benchmark::State& state) {
  const Scene& s = Scene::get();
  const int mode = int(state.range(1));
  double t_hull = 0, t_balance = 0, t_carve = 0, t_mesh = 0, t_surface = 0, t_texture = 0,
         t_encode = 0;
  double carve_iterations = 0, carve_judged = 0;
  const bool textured = mode == 2 || mode == 4;
  // Thread CPU time (every stage runs on this thread with the default threads = 1): figures
  // under the shared machine's load stay comparable.
  const auto ms = [](auto t0) {
    return std::chrono::duration<double, std::milli>(ThreadClock::now() - t0).count();
  };
  for (auto _ : state) {
    auto t0 = ThreadClock::now();
    const hull::SegmentSet set =
        hull::visual_hull(testing::studio_grid(int(state.range(0))), s.cut_views).value();
    hull::Mesh mesh;
    t_hull += ms(t0);
    t0 = ThreadClock::now();
    if (mode == 0) {
      mesh = hull_mesh(s, set);
      t_mesh += ms(t0);
    } else {
      std::vector<Image<Rgb8>> store;
      const hull::GridSpec grid = testing::studio_grid(int(state.range(0)));
      const std::vector<ColourView> views =
          apply_colour_balance(s.views, estimate_colour_balance(grid, s.views).value(), &store);
      t_balance += ms(t0);
      t0 = ThreadClock::now();
      const CarveResult carved = photo_carve(set, views).value();
      t_carve += ms(t0);
      carve_iterations += carved.iterations;
      carve_judged += double(carved.judged);
      t0 = ThreadClock::now();
      mesh = refined_mesh(carved.set, set, s.views).value();
      t_mesh += ms(t0);
    }
    if (mode >= 3) {
      t0 = ThreadClock::now();
      SurfaceRefineOptions so;
      so.cell = 3.0 / double(state.range(0));
      so.inside_hull = mode != 5;
      if (mode == 6) so.rim_band_cells = 0;
      mesh = refine_surface(mesh, s.views, so).value().mesh;
      t_surface += ms(t0);
    }
    std::vector<Eigen::Vector3f> colours;
    if (textured) {
      t0 = ThreadClock::now();
      colours = vertex_colours(mesh, s.views).value();
      t_texture += ms(t0);
    }
    t0 = ThreadClock::now();
    benchmark::DoNotOptimize(encode_frame_glb(mesh, textured ? &colours : nullptr, "actor", 45));
    t_encode += ms(t0);
  }
  const double n = double(state.iterations());
  state.counters["cut_ms"] = t_hull / n;
  state.counters["balance_ms"] = t_balance / n;
  state.counters["carve_ms"] = t_carve / n;
  if (mode != 0) {
    state.counters["carve_iterations"] = carve_iterations / n;
    state.counters["carve_judged"] = carve_judged / n;  // surface voxels judged, all iterations
  }
  state.counters["mesh_ms"] = t_mesh / n;
  state.counters["surface_ms"] = t_surface / n;
  state.counters["texture_ms"] = t_texture / n;
  state.counters["encode_ms"] = t_encode / n;
  const double frame_ms =
      (t_hull + t_balance + t_carve + t_mesh + t_surface + t_texture + t_encode) / n;
  state.counters["frames_per_min_1core"] = 60000 / frame_ms;
}
BENCHMARK(BM_Frame)
    ->ArgsProduct({{256, 512}, {0, 1, 2, 3, 4, 5, 6}})
    ->ArgNames({"grid", "mode"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

// range(0): threshold (grey levels; 0 = the hull itself, the baseline); range(1): patch_half
// (0: the colour spread alone; 3: with the shading-patch NCC test); range(2): the surface stage's
// shape steps (-1: no surface stage); range(3): its photo-term iterations.
void BM_Quality(benchmark::State& state) {
  const Scene& s = Scene::get();
  const hull::SegmentSet set = hull::visual_hull(testing::studio_grid(256), s.cut_views).value();
  CarveOptions o;
  o.threshold = double(state.range(0));
  o.patch_half = int(state.range(1));
  SurfaceRefineOptions so;
  so.cell = 3.0 / 256;
  so.shape_steps = int(std::max<int64_t>(0, state.range(2)));
  so.iterations = int(state.range(3));
  hull::Mesh mesh;
  for (auto _ : state) {
    if (state.range(0) == 0) {
      mesh = hull_mesh(s, set);
    } else {
      const CarveResult carved = photo_carve(set, s.views, o).value();
      mesh = refined_mesh(carved.set, set, s.views).value();
    }
    if (state.range(2) >= 0) mesh = refine_surface(mesh, s.views, so).value().mesh;
  }
  const auto score = testing::surface_distance(mesh, s.frame.truth.body, 100000);
  state.counters["mean_mm"] = 1e3 * score.both.mean;
  state.counters["p95_mm"] = 1e3 * score.both.p95;
  state.counters["accuracy_mean_mm"] = 1e3 * score.accuracy.mean;
  state.counters["completeness_mean_mm"] = 1e3 * score.completeness.mean;
}
BENCHMARK(BM_Quality)
    ->Args({0, 0, -1, 0})
    ->Args({0, 0, 10, 0})
    ->Args({4, 0, -1, 0})
    ->Args({6, 0, -1, 0})
    ->Args({6, 3, -1, 0})
    ->Args({6, 3, 5, 0})
    ->Args({6, 3, 10, 0})
    ->Args({6, 3, 20, 0})
    ->Args({6, 3, 10, 1})
    ->Args({9, 3, -1, 0})
    ->Args({12, 0, -1, 0})
    ->ArgNames({"threshold", "patch", "surface", "photo"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace studio::offline

BENCHMARK_MAIN();
