// Visual hull benchmark: 8 cameras (704x576) around a synthetic actor, the studio layout.
// Cut and mesh at 128x128 and 256x256 columns, one core and two, against the straightforward
// baseline in the same binary: voxel carving that projects every voxel centre (same cell size
// along all three axes) into every mask. Counters: intervals, triangles, speedup_vs_voxel (ratio
// of process CPU times, so it survives a loaded machine; with 2 threads it counts both cores).
#include <benchmark/benchmark.h>

#include <ctime>
#include <map>

#include "hull/segment_mesh.h"
#include "hull/silhouette_cut.h"
#include "support/cameras.h"
#include "testing/synthetic.h"

namespace studio::hull {
namespace {

struct Studio {
  std::vector<Camera> cameras;
  std::vector<RunMask> masks;
  std::vector<Mask> images;  // decoded masks for the baseline
  std::vector<View> views;
  Studio() {
    const testing::Scene scene = testing::actor();
    cameras = support::camera_ring(8, 704, 576, 4.0, 1.6, {0, 1, 0}, 600);
    for (const Camera& c : cameras) {
      masks.push_back(testing::render_mask(c, scene));
      images.push_back(masks.back().to_mask());
    }
    for (std::size_t k = 0; k < cameras.size(); ++k) views.push_back({&cameras[k], &masks[k]});
  }
  static const Studio& get() {
    static const Studio s;
    return s;
  }
};

GridSpec grid(int n) {
  GridSpec g;
  g.box_min = {-1, 0, -1};
  g.box_max = {1, 2, 1};
  g.cells_u = g.cells_v = n;
  return g;
}

// The baseline: every voxel centre projected into every mask (early out on the first miss).
std::size_t voxel_carving(const Studio& s, int n) {
  const GridSpec g = grid(n);
  const Eigen::Vector3d step = (g.box_max - g.box_min) / n;
  std::vector<Eigen::Matrix<double, 3, 4>> P;
  for (const Camera& c : s.cameras) P.push_back(c.projection_matrix());
  std::size_t occupied = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector4d x(g.box_min.x() + (i + 0.5) * step.x(),
                                g.box_min.y() + (j + 0.5) * step.y(),
                                g.box_min.z() + (k + 0.5) * step.z(), 1.0);
        bool in = true;
        for (std::size_t c = 0; c < P.size() && in; ++c) {
          const Eigen::Vector3d h = P[c] * x;
          const int u = int(std::floor(h.x() / h.z() + 0.5)),
                    v = int(std::floor(h.y() / h.z() + 0.5));
          const Mask& m = s.images[c];
          if (h.z() > 0 && u >= 0 && v >= 0 && u < m.width() && v < m.height()) in = m(u, v) != 0;
        }
        occupied += in;
      }
  return occupied;
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

double baseline_seconds(int n) {
  static std::map<int, double> cache;
  if (auto it = cache.find(n); it != cache.end()) return it->second;
  const Studio& s = Studio::get();
  double best = 1e9;
  for (int r = 0; r < 3; ++r) {
    const double t0 = cpu_seconds();
    benchmark::DoNotOptimize(voxel_carving(s, n));
    best = std::min(best, cpu_seconds() - t0);
  }
  return cache[n] = best;
}

void BM_Cut(benchmark::State& state) {
  const Studio& s = Studio::get();
  const int n = int(state.range(0));
  CutOptions o;
  o.threads = int(state.range(1));
  std::size_t intervals = 0;
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    auto hull = visual_hull(grid(n), s.views, o);
    intervals = hull->interval_count();
    benchmark::DoNotOptimize(hull);
  }
  const double per = (cpu_seconds() - t0) / double(state.iterations());
  state.counters["intervals"] = double(intervals);
  state.counters["speedup_vs_voxel"] = baseline_seconds(n) / per;
}
BENCHMARK(BM_Cut)
    ->Args({128, 1})
    ->Args({128, 2})
    ->Args({256, 1})
    ->Args({256, 2})
    ->Args({512, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_Mesh(benchmark::State& state) {
  const Studio& s = Studio::get();
  const auto hull = visual_hull(grid(int(state.range(0))), s.views);
  std::size_t triangles = 0;
  for (auto _ : state) {
    const Mesh m = segment_marching_cubes(*hull);
    triangles = m.triangles.size();
    benchmark::DoNotOptimize(m);
  }
  state.counters["triangles"] = double(triangles);
}
BENCHMARK(BM_Mesh)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

// The baseline itself, for the table.
void BM_VoxelCarvingBaseline(benchmark::State& state) {
  const Studio& s = Studio::get();
  for (auto _ : state) benchmark::DoNotOptimize(voxel_carving(s, int(state.range(0))));
}
BENCHMARK(BM_VoxelCarvingBaseline)->Arg(128)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace studio::hull

BENCHMARK_MAIN();
