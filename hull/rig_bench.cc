// The real-rig benchmark (issue 18): 20 cameras 1024x768 at four heights, tilted down 10-40
// degrees, some rolled (hull/testing/tilted_rig.h), the simulated studio's actor (true masks),
// a loose box 3x the actor's size with the actor in its corner, the default visibility policy.
// Baseline in the same binary: the naive voxel carve done well (testing/sim_rig.h: projection
// matrices precomputed, early rejection, the same pixel lookup, one core) at 128^3.
// Counters: intervals, speedup_vs_voxel128 (ratio of process CPU times, one core each).
#include <benchmark/benchmark.h>

#include <ctime>

#include "hull/silhouette_cut.h"
#include "testing/sim_rig.h"
#include "testing/tilted_rig.h"

namespace studio::hull {
namespace {

struct TiltedRig {
  testing::SimFrame frame;
  std::vector<View> views;
  GridSpec box;
  TiltedRig() {
    sim::Actor::Options a;
    a.seed = 3;
    a.motion = sim::Motion::walk;
    Eigen::Vector3d lo, hi;
    testing::bounds(testing::sim_actor_body(a, 20), &lo, &hi);
    frame = testing::render_sim(a, 20, testing::tilted_rig(0.5 * (lo + hi)));
    views = frame.views();
    box = testing::loose_box(lo, hi, 3, 128);
  }
  static const TiltedRig& get() {
    static const TiltedRig r;
    return r;
  }
};

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double carve_seconds() {
  static const double best = [] {
    const TiltedRig& r = TiltedRig::get();
    const testing::VoxelCarve carve(r.frame.cameras, r.frame.truth, kDefaultMinViews);
    double b = 1e9;
    for (int k = 0; k < 3; ++k) {
      const double t0 = cpu_seconds();
      benchmark::DoNotOptimize(carve.carve(r.box, 128));
      b = std::min(b, cpu_seconds() - t0);
    }
    return b;
  }();
  return best;
}

void BM_RigCut(benchmark::State& state) {
  const TiltedRig& r = TiltedRig::get();
  GridSpec g = r.box;
  g.cells_u = g.cells_v = int(state.range(0));
  CutOptions o;  // default policy, one thread
  std::size_t intervals = 0;
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    auto hull = visual_hull(g, r.views, o);
    intervals = hull->interval_count();
    benchmark::DoNotOptimize(hull);
  }
  const double per = (cpu_seconds() - t0) / double(state.iterations());
  state.counters["intervals"] = double(intervals);
  state.counters["speedup_vs_voxel128"] = carve_seconds() / per;
}
BENCHMARK(BM_RigCut)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RigVoxelCarveBaseline(benchmark::State& state) {
  const TiltedRig& r = TiltedRig::get();
  const testing::VoxelCarve carve(r.frame.cameras, r.frame.truth, kDefaultMinViews);
  std::size_t n = 0;
  for (auto _ : state) benchmark::DoNotOptimize(n = carve.carve(r.box, int(state.range(0))));
  state.counters["voxels"] = double(n);
}
BENCHMARK(BM_RigVoxelCarveBaseline)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace studio::hull
