// The live hull's frame at the demo's configuration (deploy/examples/studio/hull.yaml): the
// simulated studio's 6 cameras at 704x576 (5 on the ring + overhead, the example rig), true masks
// of the `sequence` motion, 160 x 160 columns over the 3 x 2.4 x 3 m acting area, one cut thread,
// the node's per-frame work: cut -> connected components -> segment marching cubes -> exact
// crossings (refine_crossings). Per stage the thread CPU time per frame is a counter (ms), so the
// stage shares survive a loaded machine. Baseline in the same run: the plain mesh (half-cell
// vertices, refine off), i.e. what the crossings add; BM_LiveFrame/1/2 splits the crossings over
// two threads (latency, at the cost of a thread hand-off).
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>

#include "hull/crossing_refine.h"
#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/studio.h"

namespace studio::hull {
namespace {

struct LiveStudio {
  std::vector<Camera> cameras;
  std::vector<std::vector<RunMask>> frames;  // per frame, per camera
  LiveStudio() {
    sim::StudioOptions so;
    so.actor.motion = sim::Motion::sequence;
    auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so);
    if (!studio) std::abort();
    cameras = studio->cameras();
    Mask truth;
    for (int f = 0; f < 200; f += 25) {  // 8 poses of the sequence
      std::vector<RunMask> masks;
      for (int c = 0; c < studio->camera_count(); ++c) {
        studio->render(c, f, nullptr, &truth);
        masks.push_back(RunMask::from_mask(truth.view()));
      }
      frames.push_back(std::move(masks));
    }
  }
  std::vector<View> views(std::size_t f) const {
    std::vector<View> v;
    for (std::size_t c = 0; c < cameras.size(); ++c) v.push_back({&cameras[c], &frames[f][c]});
    return v;
  }
  static const LiveStudio& get() {
    static const LiveStudio s;
    return s;
  }
};

GridSpec live_grid() {
  GridSpec g;
  g.box_min = {-1.5, 0, -1.5};
  g.box_max = {1.5, 2.4, 1.5};
  g.axis = Axis::y;
  g.cells_u = g.cells_v = 160;
  return g;
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * double(t.tv_sec) + 1e-6 * double(t.tv_nsec);
}

// Args: refine (0 plain, 1 exact crossings); refine threads; 1 = the mesh skips its normals when
// the crossings recompute them (the node's way), 0 = computed twice (before); threads of the
// segment marching cubes (the node gives it its `threads`). Wall time per stage as *_wall_ms: what
// a split buys in latency.
void BM_LiveFrame(benchmark::State& state) {
  const LiveStudio& s = LiveStudio::get();
  const bool refine = state.range(0) != 0;
  const bool skip_normals = state.range(2) != 0;  // normals once, after the crossings
  CutOptions cut;
  cut.threads = 1;
  CutOptions refine_options = cut;
  refine_options.threads = int(state.range(1));
  const int mesh_threads = int(state.range(3));
  double ms[4] = {0, 0, 0, 0}, wall[3] = {0, 0, 0};
  using Wall = std::chrono::steady_clock;
  const auto since = [](Wall::time_point& t) {
    const auto now = Wall::now();
    const double d = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return d;
  };
  std::size_t frame = 0, triangles = 0;
  for (auto _ : state) {
    const std::vector<View> views = s.views(frame++ % s.frames.size());
    double t = thread_cpu_ms();
    auto w = Wall::now();
    auto hull = visual_hull(live_grid(), views, cut);
    const std::vector<SegmentSet> actors = connected_components(*hull, 0.01);
    double now = thread_cpu_ms();
    ms[0] += now - t, t = now;
    wall[0] += since(w);
    for (const SegmentSet& actor : actors) {
      Mesh mesh = segment_marching_cubes(
          actor, {.normals = !refine || !skip_normals, .threads = mesh_threads});
      now = thread_cpu_ms();
      ms[1] += now - t, t = now;
      wall[1] += since(w);
      if (refine) {
        if (!refine_crossings(mesh, actor, views, refine_options)) state.SkipWithError("refine");
        now = thread_cpu_ms();
        ms[2] += now - t, t = now;
        wall[2] += since(w);
      }
      triangles += mesh.triangles.size();
      benchmark::DoNotOptimize(mesh);
    }
  }
  const double n = double(state.iterations());
  state.counters["cut_ms"] = ms[0] / n;
  state.counters["mesh_ms"] = ms[1] / n;
  state.counters["refine_ms"] = ms[2] / n;  // main thread only when split
  state.counters["cpu_ms"] = (ms[0] + ms[1] + ms[2]) / n;
  state.counters["mesh_wall_ms"] = wall[1] / n;
  state.counters["refine_wall_ms"] = wall[2] / n;
  state.counters["wall_ms"] = (wall[0] + wall[1] + wall[2]) / n;
  state.counters["triangles"] = double(triangles) / n;
}
BENCHMARK(BM_LiveFrame)
    ->Args({0, 1, 0, 1})
    ->Args({1, 1, 0, 1})
    ->Args({1, 1, 1, 1})
    ->Args({1, 2, 1, 1})
    ->Args({1, 2, 1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace studio::hull
