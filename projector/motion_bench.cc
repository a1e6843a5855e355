// The projector's per-mesh motion estimate (projector/motion.h) on meshes of the simulated actor
// swinging its arm at 1.5 m/s (sim/ arm_swing), at about the hull's mesh size in the demo (the
// body's parts tessellated to ~10k vertices), 25 Hz: what the node pays for every mesh. Baseline
// in the same run: the same fit on every vertex (fit_vertices = global_fit_vertices = 0, the
// estimate before the budget), so the ratio is the budget's gain.
#include <benchmark/benchmark.h>

#include "projector/motion.h"
#include "testing/swing_meshes.h"

using namespace studio;

namespace {

constexpr int64_t kFrameNs = projector::testing::kSwingFrameNs;

using projector::testing::swing_meshes;

void run(benchmark::State& state, const projector::MotionOptions& options) {
  const auto& m = swing_meshes();
  projector::MotionTracker tracker(options);
  int64_t shift = 0;
  size_t k = 0;
  for (auto _ : state) {
    projector::ActorMesh mesh = m[k % m.size()];
    mesh.capture_ns += shift;  // keeps capture times increasing when the sequence wraps
    if (++k % m.size() == 0) shift += int64_t(m.size()) * kFrameNs;
    auto r = tracker.update(mesh);
    if (!r) state.SkipWithError(r.error().message.c_str());
    benchmark::DoNotOptimize(r);
  }
  state.counters["vertices"] = double(m[0].vertices.size());
}

void BM_MotionEveryVertex(benchmark::State& state) {
  projector::MotionOptions o;
  o.fit_vertices = 0;
  o.global_fit_vertices = 0;
  o.converged_m = 1e-7;  // the fit before the budget
  run(state, o);
}
BENCHMARK(BM_MotionEveryVertex)->Unit(benchmark::kMillisecond)->MinTime(2);

void BM_MotionBudget(benchmark::State& state) { run(state, {}); }
BENCHMARK(BM_MotionBudget)->Unit(benchmark::kMillisecond)->MinTime(2);

void BM_MotionBudgetArgs(benchmark::State& state) {
  projector::MotionOptions o;
  o.fit_vertices = int(state.range(0));
  o.global_fit_vertices = int(state.range(1));
  o.iterations = int(state.range(2));
  run(state, o);
}
BENCHMARK(BM_MotionBudgetArgs)
    ->Args({24, 300, 15})
    ->Args({48, 600, 8})
    ->Args({24, 300, 8})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1);

}  // namespace

BENCHMARK_MAIN();
