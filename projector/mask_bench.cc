// The projector's mask cost per mesh and per frame (projector/mask_planner.h), on meshes of the
// simulated actor swinging its arm at 1.5 m/s (~11k vertices, 25 Hz, as motion_bench.cc):
//   BM_FrameMask_SimplifyPerFrame  baseline, what plan() did before: the whole mesh moved forward
//                                  by its motion, then simplified (meshoptimizer) and grown —
//                                  for every frame drawn
//   BM_FrameMask_SimplifiedOnce    plan() now: the mesh simplified once (set_mesh), per frame only
//                                  the simplified mesh moved forward and grown
//   BM_SetMesh                     MaskPlanner::set_mesh per mesh: motion estimate + simplification
//   BM_MeshAndFrame/<old|new>      one mesh and the frame drawn with it, the node's unit of work
//                                  (set_mesh + plan), before and after
#include <benchmark/benchmark.h>

#include <algorithm>
#include <string>

#include "projector/mask_geometry.h"
#include "projector/mask_planner.h"
#include "projector/motion.h"
#include "projector/velocity_field.h"
#include "testing/hull_meshes.h"
#include "testing/projectors.h"
#include "testing/swing_meshes.h"

using namespace studio;

namespace {

constexpr int64_t kFrameNs = projector::testing::kSwingFrameNs;
constexpr double kMargin = 0.03;

using projector::testing::swing_meshes;

// The last two meshes' motion (what plan() predicts with).
const projector::MeshMotion& motion() {
  static const projector::MeshMotion m = [] {
    projector::MotionTracker t;
    (void)t.update(swing_meshes()[0]);
    (void)t.update(swing_meshes()[1]);
    return t.update(swing_meshes()[2]).value().value();
  }();
  return m;
}

void BM_FrameMask_SimplifyPerFrame(benchmark::State& state) {
  const auto& mesh = swing_meshes()[2];
  for (auto _ : state) {
    auto moved = projector::predict(mesh, motion(), 0.06);
    auto grown = projector::grow_mesh(*moved, kMargin);
    benchmark::DoNotOptimize(grown);
  }
  state.counters["triangles_in"] = double(mesh.triangles.size());
}
BENCHMARK(BM_FrameMask_SimplifyPerFrame)->Unit(benchmark::kMillisecond)->MinTime(1);

void BM_FrameMask_SimplifiedOnce(benchmark::State& state) {
  const auto base = projector::simplify_for_mask(swing_meshes()[2]).value();
  std::vector<Eigen::Vector3f> velocities;  // the motion's, per vertex of the simplified mesh
  for (uint32_t i : base.source) velocities.push_back(motion().velocity(i));
  for (auto _ : state) {
    auto moved = projector::predict_by_velocities(base.mesh, velocities, 0.06);
    auto grown = projector::grow_mask({std::move(*moved), base.error_m, {}}, kMargin);
    benchmark::DoNotOptimize(grown);
  }
  state.counters["triangles_drawn"] = double(base.mesh.triangles.size());
}
BENCHMARK(BM_FrameMask_SimplifiedOnce)->Unit(benchmark::kMillisecond)->MinTime(1);

// Meshes fed to a planner with increasing capture times (wrapping the sequence).
struct Feed {
  int64_t shift = 0;
  size_t k = 0;
  projector::ActorMesh next() {
    const auto& m = swing_meshes();
    projector::ActorMesh mesh = m[k % m.size()];
    mesh.capture_ns += shift;
    if (++k % m.size() == 0) shift += int64_t(m.size()) * kFrameNs;
    return mesh;
  }
};

void BM_SetMesh(benchmark::State& state) {
  projector::MaskPlanner planner;
  Feed feed;
  for (auto _ : state) {
    auto ok = planner.set_mesh("actor0", feed.k, feed.next());
    if (!ok) state.SkipWithError(ok.error().message.c_str());
  }
  state.counters["motion_ms"] = planner.last_mesh_cost().motion_s * 1e3;
  state.counters["simplify_ms"] = planner.last_mesh_cost().simplify_s * 1e3;
}
BENCHMARK(BM_SetMesh)->Unit(benchmark::kMillisecond)->MinTime(2)->MeasureProcessCPUTime();

// set_mesh's two stages one after the other with the edge collapse alone (the baseline: before
// session 9), with the clustering first, and both on two threads (the default; process CPU).
void BM_SetMeshStages(benchmark::State& state) {
  projector::MaskPlannerOptions o;
  o.grow.presimplify = state.range(0) != 0;
  o.parallel_mesh_work = state.range(1) != 0;
  projector::MaskPlanner planner(o);
  Feed feed;
  for (auto _ : state) {
    auto ok = planner.set_mesh("actor0", feed.k, feed.next());
    if (!ok) state.SkipWithError(ok.error().message.c_str());
  }
  state.SetLabel(std::string(o.grow.presimplify ? "clustered+collapse" : "collapse") +
                 (o.parallel_mesh_work ? ", parallel" : ", serial"));
}
BENCHMARK(BM_SetMeshStages)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// One mesh and its frame. old: the motion estimate, then for the frame the whole mesh predicted,
// simplified and grown (the planner before); new: MaskPlanner::set_mesh + plan.
void BM_MeshAndFrame(benchmark::State& state) {
  const bool old = state.range(0) == 0;
  projector::MaskPlanner planner;
  projector::MotionTracker tracker;
  Feed feed;
  for (auto _ : state) {
    projector::ActorMesh mesh = feed.next();
    const int64_t display_ns = mesh.capture_ns + 60'000'000;
    if (old) {
      auto m = tracker.update(mesh);
      if (m && *m) {
        auto moved = projector::predict(mesh, **m, 0.06);
        auto grown = projector::grow_mesh(*moved, kMargin);
        benchmark::DoNotOptimize(grown);
      }
    } else {
      (void)planner.set_mesh("actor0", feed.k, std::move(mesh));
      auto plan = planner.plan(display_ns);
      benchmark::DoNotOptimize(plan);
    }
  }
  state.SetLabel(old ? "old: simplify per frame" : "new: simplify per mesh");
}
BENCHMARK(BM_MeshAndFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(2);

// The mask's simplification per mesh (simplify_for_mask) on the hull's own meshes of the arm
// swing (testing/hull_meshes.h, ~35-40k triangles as live), by GrowOptions: args max_triangles,
// cluster_factor (presimplify on). Counters: the triangles drawn, the error added to the margin
// (error_mm, the mean over meshes) and the largest.
void BM_SimplifyHull(benchmark::State& state) {
  static const std::vector<projector::ActorMesh> meshes =
      projector::testing::hull_meshes(sim::Motion::arm_swing, 50, 8);
  projector::GrowOptions o;
  o.max_triangles = std::size_t(state.range(0));
  o.cluster_factor = std::size_t(state.range(1));
  std::size_t k = 0;
  double error = 0, worst = 0, drawn = 0, in = 0;
  for (auto _ : state) {
    const projector::ActorMesh& mesh = meshes[k++ % meshes.size()];
    auto base = projector::simplify_for_mask(mesh, o);
    if (!base) {
      state.SkipWithError(base.error().message.c_str());
      break;
    }
    error += base->error_m;
    worst = std::max(worst, base->error_m);
    drawn += double(base->mesh.triangles.size());
    in += double(mesh.triangles.size());
  }
  const double n = double(std::max<std::size_t>(k, 1));
  state.counters["error_mm"] = 1e3 * error / n;
  state.counters["worst_error_mm"] = 1e3 * worst;
  state.counters["triangles_drawn"] = drawn / n;
  state.counters["triangles_in"] = in / n;
}
BENCHMARK(BM_SimplifyHull)
    ->Args({3000, 4})
    ->Args({3000, 2})
    ->Args({3000, 1})
    ->Args({6000, 1})
    ->Args({8000, 1})
    ->Args({12000, 1})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1)
    ->MeasureProcessCPUTime();

// The outline form per frame (grow_outline, no GL) on the hull's arm-swing meshes as the node
// grows them (whole, GrowOptions::simplify_outline false): the back-wall projector at 1280x720,
// margin arg 0 mm. Counters: triangles in, quads out.
void BM_GrowOutlineHull(benchmark::State& state) {
  static const std::vector<projector::ActorMesh> meshes =
      projector::testing::hull_meshes(sim::Motion::arm_swing, 50, 8);
  Camera cam = projector::testing::studio_projectors().front().camera;
  const double k = 1280.0 / cam.width;
  cam.intrinsics.fx *= k;
  cam.intrinsics.fy *= k;
  cam.intrinsics.cx = (cam.intrinsics.cx + 0.5) * k - 0.5;
  cam.intrinsics.cy = (cam.intrinsics.cy + 0.5) * k - 0.5;
  cam.width = 1280;
  cam.height = 720;
  std::size_t n = 0;
  double quads = 0, triangles = 0;
  for (auto _ : state) {
    const projector::ActorMesh& m = meshes[n++ % meshes.size()];
    auto grown = projector::grow_outline(m, 1e-3 * double(state.range(0)), cam);
    if (!grown) {
      state.SkipWithError(grown.error().message.c_str());
      break;
    }
    quads += 0.5 * double(grown->triangles.size());
    triangles += double(m.triangles.size());
  }
  state.counters["triangles_in"] = triangles / double(std::max<std::size_t>(n, 1));
  state.counters["quads"] = quads / double(std::max<std::size_t>(n, 1));
}
BENCHMARK(BM_GrowOutlineHull)->Arg(30)->Arg(130)->Arg(200)->Unit(benchmark::kMillisecond)->MinTime(1);

}  // namespace

BENCHMARK_MAIN();
