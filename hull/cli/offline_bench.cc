// The offline frame (studio-hull offline, per frame after reading): key 6 camera frames of the
// simulated studio (704x576, the default rig) -> cut -> segment marching cubes -> exact crossings,
// at 256x256 and 512x512 columns. Baselines in the same binary:
// - refine_over_mesh: the exact crossings' cost relative to the plain mesh (BM_Mesh), i.e. what
//   the default (no --no-refine) adds to the mesh stage;
// - speedup_2_threads: one frame's cut + refine with 2 threads vs 1 (a single-frame run); a
//   sequence runs whole frames in parallel instead (BM_OfflineFrame/*/2 = two frames at once,
//   frames_per_s counts both).
#include <benchmark/benchmark.h>

#include <map>
#include <thread>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "keyer/keyer.h"
#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::hull {
namespace {

struct Scene {
  std::vector<Camera> cameras;
  std::vector<Image<Rgb8>> images;
  std::vector<RunMask> masks;  // keyed
  std::vector<View> views;

  Scene() {
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), {}).value();
    cameras = studio.cameras();
    images.resize(cameras.size());
    masks.resize(cameras.size());
    auto keyer = keyer::Keyer::create({}).value();
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      studio.render(int(c), 30, &images[c], nullptr);
      (void)keyer.key(images[c].view(), masks[c]);
    }
    for (std::size_t c = 0; c < cameras.size(); ++c) views.push_back({&cameras[c], &masks[c]});
  }
  static const Scene& get() {
    static const Scene s;
    return s;
  }
};

GridSpec grid(int n) {
  GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = Axis::y;
  g.cells_u = g.cells_v = n;
  return g;
}

template <class F>
double seconds_per_call(F&& f, int reps) {
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / reps;
}

// The plain mesh (the baseline of the refine cost).
void BM_Mesh(benchmark::State& state) {
  const Scene& s = Scene::get();
  const SegmentSet set = visual_hull(grid(int(state.range(0))), s.views).value();
  for (auto _ : state) benchmark::DoNotOptimize(segment_marching_cubes(set));
}
BENCHMARK(BM_Mesh)->Arg(256)->Arg(512)->Unit(benchmark::kMillisecond)->UseRealTime();

// Exact crossings on that mesh (the mesh copy it starts from is included); threads = range(1).
// refine_over_mesh = refine time / plain mesh time; speedup_vs_1_thread = 1-thread refine time /
// this one's (both timed outside the loop the same way, so the ratios survive a busy machine).
void BM_Refine(benchmark::State& state) {
  const Scene& s = Scene::get();
  const SegmentSet set = visual_hull(grid(int(state.range(0))), s.views).value();
  const Mesh plain = segment_marching_cubes(set);
  CutOptions o;
  o.threads = int(state.range(1));
  const auto refine = [&](const CutOptions& options) {
    Mesh m = plain;
    (void)refine_crossings(m, set, s.views, options);
    benchmark::DoNotOptimize(m);
  };
  for (auto _ : state) refine(o);
  const double mesh_s =
      seconds_per_call([&] { benchmark::DoNotOptimize(segment_marching_cubes(set)); }, 3);
  const double refine_s = seconds_per_call([&] { refine(o); }, 3);
  const double one_s =
      o.threads == 1 ? refine_s : seconds_per_call([&] { refine(CutOptions{}); }, 3);
  state.counters["vertices"] = double(plain.vertices.size());
  state.counters["refine_over_mesh"] = refine_s / mesh_s;
  state.counters["speedup_vs_1_thread"] = one_s / refine_s;
}
BENCHMARK(BM_Refine)
    ->Args({256, 1})
    ->Args({512, 1})
    ->Args({512, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// One whole offline frame after reading: key 6 frames, cut, mesh, refine, single-threaded.
// range(1) = workers running frames at once (a sequence on both cores); frames_per_s counts all
// of them and speedup_vs_1_worker compares with one worker timed the same way.
void BM_OfflineFrame(benchmark::State& state) {
  const Scene& s = Scene::get();
  const GridSpec g = grid(int(state.range(0)));
  const int workers = int(state.range(1));
  const auto frame = [&] {
    std::vector<RunMask> masks(s.cameras.size());
    std::vector<View> views;
    auto keyer = keyer::Keyer::create({}).value();
    for (std::size_t c = 0; c < s.cameras.size(); ++c) {
      (void)keyer.key(s.images[c].view(), masks[c]);
      views.push_back({&s.cameras[c], &masks[c]});
    }
    const SegmentSet set = visual_hull(g, views).value();
    Mesh m = segment_marching_cubes(set);
    (void)refine_crossings(m, set, views);
    benchmark::DoNotOptimize(m);
  };
  const auto batch = [&](int n) {
    std::vector<std::jthread> pool;
    for (int k = 1; k < n; ++k) pool.emplace_back(frame);
    frame();
  };
  for (auto _ : state) batch(workers);
  const double one = seconds_per_call([&] { batch(1); }, 2);
  const double all = workers == 1 ? one : seconds_per_call([&] { batch(workers); }, 2);
  state.counters["frames_per_s"] =
      benchmark::Counter(double(workers), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["speedup_vs_1_worker"] = workers * one / all;
}
BENCHMARK(BM_OfflineFrame)
    ->Args({512, 1})
    ->Args({512, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace studio::hull

BENCHMARK_MAIN();
