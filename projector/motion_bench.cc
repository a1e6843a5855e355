// The projector's per-mesh motion estimate (projector/motion.h): what the node pays for every mesh.
//
// Live-like meshes (BM_MotionHull*): the hull's own meshes of the simulated actor swinging its
// arm at 1.5 m/s (sim/ arm_swing, true masks of the 6-camera ring -> silhouette cut at the demo's
// 160 columns -> segment marching cubes -> exact crossings; testing/hull_meshes.h), ~29k
// triangles, 25 Hz, played forward and back; the demo's live meshes are 35-51k triangles.
// Counters: closest-point queries, fits and ICP iterations per mesh.
// BM_MotionHullConverged: the default fit and a variant (ICP convergence threshold arg 0 in um,
// iteration cap arg 1) interleaved mesh by mesh on two trackers (same conditions): thread CPU
// per mesh of each, the ratio, and how far the variant's velocity field is from the default's
// (per vertex, m/s).
//
// Tessellated simulated body (BM_MotionEveryVertex, BM_MotionBudget; testing/swing_meshes.h,
// ~11k vertices): the earlier figures' input, kept for comparison with BENCHMARKS.md.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "projector/motion.h"
#include "testing/hull_meshes.h"
#include "testing/swing_meshes.h"

using namespace studio;

namespace {

constexpr int64_t kFrameNs = projector::testing::kSwingFrameNs;

using projector::testing::swing_meshes;

const std::vector<projector::ActorMesh>& hull_swing() {
  // Frames 50-65 (2.0-2.6 s): the swing's fast part.
  static const std::vector<projector::ActorMesh> m =
      projector::testing::hull_meshes(sim::Motion::arm_swing, 50, 16);
  return m;
}

double thread_cpu() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}

// The k-th mesh of the sequence played forward and back (0 1 .. n-1 n-2 .. 1 0 1 ..: every
// pair is two consecutive frames, never a jump back to the start), captured 40 ms apart.
projector::ActorMesh nth(const std::vector<projector::ActorMesh>& m, size_t k) {
  const size_t period = 2 * m.size() - 2, phase = k % period;
  projector::ActorMesh mesh = m[phase < m.size() ? phase : period - phase];
  mesh.capture_ns = m.front().capture_ns + int64_t(k) * kFrameNs;
  return mesh;
}

void run(benchmark::State& state, const std::vector<projector::ActorMesh>& m,
         const projector::MotionOptions& options) {
  projector::MotionTracker tracker(options);
  size_t k = 0;
  double triangles = 0, queries = 0, fits = 0, iterations = 0, motions = 0;
  for (auto _ : state) {
    state.PauseTiming();
    projector::ActorMesh mesh = nth(m, k++);
    triangles += double(mesh.triangles.size());
    state.ResumeTiming();
    auto r = tracker.update(mesh);
    if (!r) {
      state.SkipWithError(r.error().message.c_str());
      break;
    }
    if (*r) {
      queries += double((*r)->closest_queries);
      fits += (*r)->fits;
      iterations += (*r)->iterations;
      ++motions;
    }
    benchmark::DoNotOptimize(r);
  }
  state.counters["vertices"] = double(m[0].vertices.size());
  state.counters["triangles"] = triangles / double(std::max<size_t>(k, 1));
  state.counters["queries_per_mesh"] = queries / std::max(motions, 1.0);
  state.counters["fits_per_mesh"] = fits / std::max(motions, 1.0);
  state.counters["iterations_per_fit"] = iterations / std::max(fits, 1.0);
}

void BM_MotionEveryVertex(benchmark::State& state) {
  projector::MotionOptions o;
  o.fit_vertices = 0;
  o.global_fit_vertices = 0;
  o.converged_m = 1e-7;  // the fit before the budget
  run(state, swing_meshes(), o);
}
BENCHMARK(BM_MotionEveryVertex)->Unit(benchmark::kMillisecond)->MinTime(2);

void BM_MotionBudget(benchmark::State& state) { run(state, swing_meshes(), {}); }
BENCHMARK(BM_MotionBudget)->Unit(benchmark::kMillisecond)->MinTime(2);

void BM_MotionHull(benchmark::State& state) { run(state, hull_swing(), {}); }
BENCHMARK(BM_MotionHull)->Unit(benchmark::kMillisecond)->MinTime(2);

// The default fit and `options` on every mesh, interleaved (same conditions): CPU per mesh of
// each, the ratio, and the difference of their velocity fields over all vertices of all meshes
// (mean and max, m/s).
void compare(benchmark::State& state, const projector::MotionOptions& options);
void BM_MotionHullConverged(benchmark::State& state) {
  projector::MotionOptions o;
  o.converged_m = 1e-6 * double(state.range(0));
  o.iterations = int(state.range(1));
  compare(state, o);
}
BENCHMARK(BM_MotionHullConverged)
    ->Args({10, 15})
    ->Args({100, 15})
    ->Args({300, 15})
    ->Args({1000, 15})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2);

void compare(benchmark::State& state, const projector::MotionOptions& options) {
  const auto& m = hull_swing();
  projector::MotionTracker variant{options};
  projector::MotionTracker baseline{projector::MotionOptions{}};
  double cpu_variant = 0, cpu_default = 0, diff_sum = 0, diff_max = 0, speed_sum = 0;
  int64_t meshes = 0, compared = 0;
  size_t k = 0;
  for (auto _ : state) {
    const projector::ActorMesh mesh = nth(m, k++);
    const bool variant_first = k % 2 == 0;  // alternate which runs first
    double t0 = thread_cpu();
    auto a = variant_first ? variant.update(mesh) : baseline.update(mesh);
    const double t1 = thread_cpu();
    auto b = variant_first ? baseline.update(mesh) : variant.update(mesh);
    const double t2 = thread_cpu();
    if (!a || !b) {
      state.SkipWithError("motion failed");
      break;
    }
    cpu_variant += variant_first ? t1 - t0 : t2 - t1;
    cpu_default += variant_first ? t2 - t1 : t1 - t0;
    ++meshes;
    const auto& fast = variant_first ? *a : *b;
    const auto& slow = variant_first ? *b : *a;
    // Not the first mesh after a reversal of the sequence (an instant turnaround of the
    // velocity, which no actor makes).
    const size_t phase = (k - 1) % (2 * m.size() - 2);
    if (fast && slow && phase != 1 && phase != m.size()) {
      for (size_t v = 0; v < mesh.vertices.size(); ++v) {
        const double d = double((fast->velocity(v) - slow->velocity(v)).norm());
        diff_sum += d;
        diff_max = std::max(diff_max, d);
        speed_sum += double(slow->velocity(v).norm());
        ++compared;
      }
    }
  }
  state.counters["variant_cpu_ms_per_mesh"] =
      1e3 * cpu_variant / double(std::max<int64_t>(meshes, 1));
  state.counters["default_cpu_ms_per_mesh"] =
      1e3 * cpu_default / double(std::max<int64_t>(meshes, 1));
  state.counters["speedup"] = cpu_default / std::max(cpu_variant, 1e-12);
  state.counters["velocity_diff_mean_mps"] = diff_sum / double(std::max<int64_t>(compared, 1));
  state.counters["velocity_diff_max_mps"] = diff_max;
  state.counters["default_speed_mean_mps"] = speed_sum / double(std::max<int64_t>(compared, 1));
  state.counters["vertices"] = double(m[0].vertices.size());
  state.counters["triangles"] = double(m[0].triangles.size());
}

}  // namespace

BENCHMARK_MAIN();
