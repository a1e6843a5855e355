// Head tracker benchmarks (./studio bench tracker): the full-volume template search (TCSVT 2004
// §IV-D; the paper ran ~5 searches/s at 64x64 columns) by branch and bound over an integral volume,
// against the exhaustive evaluation of M(P) at every position (same binary: the "speedup" counter).
//
// A search = integral volume build + exact maximum over every template position + NMS +
// sub-voxel centre. Grids: 128 columns over a 3 m x 2.4 m x 3 m studio (2.34 cm voxels),
// either the occupied part only (what the hull's rasteriser hands over) or the whole studio.

#include <benchmark/benchmark.h>

#include <chrono>
#include <map>

#include "core/run_mask.h"
#include "hull/silhouette_cut.h"
#include "sim/cameras.h"
#include "sim/studio.h"
#include "testing/synthetic_actor.h"
#include "tracker/head_search.h"
#include "tracker/segment_raster.h"

namespace studio::tracker {
namespace {

OccupancyGrid scene(int columns, int actors, bool cropped) {
  OccupancyGrid g = make_grid({-1.5, 0, -1.5}, {1.5, 2.4, 1.5}, columns);
  const Eigen::Vector2d at[3] = {{0.1, 0.2}, {-0.9, -0.6}, {0.9, -0.5}};
  for (int i = 0; i < actors; ++i) {
    testing::SyntheticActor a;
    a.floor_xz = at[i];
    a.hand_raised = i == 0;
    a.yaw = 0.4 * i;
    testing::add_actor(g, a);
  }
  return cropped ? g.cropped_to_occupied() : g;
}

double seconds_per_exhaustive(HeadSearch& s, const OccupancyGrid& g) {
  const auto t0 = std::chrono::steady_clock::now();
  int n = 0;
  do {
    benchmark::DoNotOptimize(s.find_exhaustive(g));
    ++n;
  } while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(300));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n;
}

// The visual hull of the simulated studio (6 cameras, actor with the right hand raised, frame
// 50 of raise_hand) on columns x columns over 3.2 m x 2.6 m x 3.2 m: the tracker's real input.
const hull::SegmentSet& sim_hull(int columns) {
  static std::map<int, hull::SegmentSet> cache;
  if (auto it = cache.find(columns); it != cache.end()) return it->second;
  sim::StudioOptions so;
  so.actor.motion = sim::Motion::raise_hand;
  so.actor.seed = 5;
  auto studio = sim::SimulatedStudio::create(sim::ring_cameras(), so).value();
  std::vector<Mask> masks;
  studio.render_all(50, nullptr, &masks);
  std::vector<RunMask> runs;
  for (const Mask& m : masks) runs.push_back(RunMask::from_mask(m.view()));
  std::vector<hull::View> views;
  for (std::size_t c = 0; c < runs.size(); ++c) views.push_back({&studio.cameras()[c], &runs[c]});
  hull::GridSpec spec;
  spec.box_min = {-1.6, 0, -1.6};
  spec.box_max = {1.6, 2.6, 1.6};
  spec.cells_u = spec.cells_v = columns;
  return cache.emplace(columns, hull::visual_hull(spec, views).value()).first->second;
}

// The tracker's whole per-frame work on the hull: rasterise the SegmentSet (cropped to the
// occupied part), integral volume, exact template search over every position, NMS, centre.
// Counter speedup = time of the same with the exhaustive search / this (same binary).
void BM_LocateFromHull(benchmark::State& state) {
  const hull::SegmentSet& set = sim_hull(int(state.range(0)));
  HeadSearch s = HeadSearch::create(HeadSearchOptions{}).value();
  OccupancyGrid grid;
  std::size_t heads = 0;
  for (auto _ : state) {
    rasterise(set, &grid);
    heads = s.find(grid).size();
  }
  state.SetItemsProcessed(state.iterations());  // items/s = full searches per second
  state.counters["heads"] = double(heads);
  state.counters["voxels"] = double(grid.size());
  state.counters["bounds"] = double(s.stats().bounds);
  const auto time = [&](bool exhaustive) {
    const auto t0 = std::chrono::steady_clock::now();
    int n = 0;
    do {
      rasterise(set, &grid);
      benchmark::DoNotOptimize(exhaustive ? s.find_exhaustive(grid) : s.find(grid));
      ++n;
    } while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(400));
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n;
  };
  const double fast = time(false), slow = time(true);
  state.counters["exhaustive_per_s"] = 1.0 / slow;
  state.counters["speedup"] = slow / fast;
}

void BM_Rasterise(benchmark::State& state) {
  const hull::SegmentSet& set = sim_hull(int(state.range(0)));
  OccupancyGrid grid;
  for (auto _ : state) rasterise(set, &grid);
  state.SetItemsProcessed(state.iterations());
  state.counters["intervals"] = double(set.interval_count());
}

// args: columns, actors, cropped
void BM_HeadSearch(benchmark::State& state) {
  const OccupancyGrid g = scene(int(state.range(0)), int(state.range(1)), state.range(2) != 0);
  HeadSearchOptions o;
  o.max_heads = 4;
  HeadSearch s = HeadSearch::create(o).value();
  std::size_t heads = 0;
  for (auto _ : state) {
    const auto found = s.find(g);
    heads = found.size();
    benchmark::DoNotOptimize(found.data());
  }
  state.SetItemsProcessed(state.iterations());  // items/s = full searches per second
  state.counters["heads"] = double(heads);
  state.counters["bounds"] = double(s.stats().bounds);
  state.counters["voxels"] = double(g.size());
}

void BM_HeadSearchVsExhaustive(benchmark::State& state) {
  const OccupancyGrid g = scene(int(state.range(0)), int(state.range(1)), state.range(2) != 0);
  HeadSearch s = HeadSearch::create(HeadSearchOptions{}).value();
  for (auto _ : state) benchmark::DoNotOptimize(s.find(g).data());
  const auto t0 = std::chrono::steady_clock::now();
  int n = 0;
  do {
    benchmark::DoNotOptimize(s.find(g).data());
    ++n;
  } while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(300));
  const double fast =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / n;
  const double slow = seconds_per_exhaustive(s, g);
  state.SetItemsProcessed(state.iterations());
  state.counters["exhaustive_per_s"] = 1.0 / slow;
  state.counters["speedup"] = slow / fast;
}

void BM_Exhaustive(benchmark::State& state) {
  const OccupancyGrid g = scene(int(state.range(0)), int(state.range(1)), state.range(2) != 0);
  HeadSearch s = HeadSearch::create(HeadSearchOptions{}).value();
  for (auto _ : state) benchmark::DoNotOptimize(s.find_exhaustive(g).data());
  state.SetItemsProcessed(state.iterations());
  state.counters["positions"] = double(s.stats().bounds);
}

void BM_IntegralVolume(benchmark::State& state) {
  const OccupancyGrid g = scene(int(state.range(0)), 1, state.range(1) != 0);
  IntegralVolume iv;
  for (auto _ : state) {
    iv.build(g);
    benchmark::DoNotOptimize(iv.total());
  }
  state.SetItemsProcessed(state.iterations() * int64_t(g.size()));
}

}  // namespace

BENCHMARK(BM_LocateFromHull)->ArgName("columns")->Arg(64)->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Rasterise)->ArgName("columns")->Arg(128)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HeadSearch)
    ->ArgNames({"columns", "actors", "cropped"})
    ->Args({64, 1, 1})
    ->Args({128, 1, 1})
    ->Args({128, 3, 1})
    ->Args({128, 1, 0})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_HeadSearchVsExhaustive)
    ->ArgNames({"columns", "actors", "cropped"})
    ->Args({128, 1, 1})
    ->Iterations(1)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Exhaustive)
    ->ArgNames({"columns", "actors", "cropped"})
    ->Args({64, 1, 1})
    ->Args({128, 1, 1})
    ->Args({128, 1, 0})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_IntegralVolume)
    ->ArgNames({"columns", "cropped"})
    ->Args({128, 1})
    ->Args({128, 0})
    ->Unit(benchmark::kMicrosecond);

}  // namespace studio::tracker

BENCHMARK_MAIN();
