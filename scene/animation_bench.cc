// Animation evaluation of 1 000 animated nodes per studio frame (the scene server's per-frame
// work): the library (binary-searched keys, one pass of world transforms parents-first, change
// set) against a naive evaluator in the same run (keys found by a linear scan from the first,
// each node's world transform recomputed by walking up to the root).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "scene/scene.h"

using namespace studio::scene;

namespace {

constexpr int kKeys = 64;

// 10 groups x 10 sub-groups x 10 animated leaves = 1 000 animated nodes (plus 110 groups), one
// animation per group driving its 100 leaves' translation and rotation (64 keys each, 8 s loop).
Scene make_scene(int animated) {
  Scene s;
  std::int64_t f = 0;
  const int groups = std::max(1, animated / 100);
  for (int g = 0; g < groups; ++g) {
    Node group;
    group.id = "g" + std::to_string(g);
    group.local.translation = {g * 1.0, 0, 0};
    (void)s.apply({f, AddNode{group}});
    Animation a;
    a.name = "anim" + std::to_string(g);
    a.mode = PlayMode::loop;
    for (int k = 0; k < 10; ++k) {
      Node sub;
      sub.id = group.id + "/s" + std::to_string(k);
      sub.parent = group.id;
      sub.local.rotation = Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitY());
      (void)s.apply({f, AddNode{sub}});
      for (int j = 0; j < 10; ++j) {
        Node leaf;
        leaf.id = sub.id + "/n" + std::to_string(j);
        leaf.parent = sub.id;
        (void)s.apply({f, AddNode{leaf}});
        Track t, r;
        t.node = r.node = leaf.id;
        t.path = TrackPath::translation;
        r.path = TrackPath::rotation;
        for (int key = 0; key < kKeys; ++key) {
          const double time = key * 8.0 / (kKeys - 1), phase = 0.37 * j + 0.11 * k;
          t.times.push_back(time);
          r.times.push_back(time);
          t.values.emplace_back(std::sin(time + phase), 1 + 0.2 * std::cos(time), j * 0.1, 0);
          const Eigen::Quaterniond q(Eigen::AngleAxisd(time + phase, Eigen::Vector3d::UnitY()));
          r.values.push_back(q.coeffs());
        }
        a.tracks.push_back(t);
        a.tracks.push_back(r);
      }
    }
    (void)s.apply({f, AddAnimation{a}});
  }
  (void)s.apply({0, Play{""}});
  return s;
}

// The library, as the server runs it each frame: Tick, world transforms, change set.
void BM_SceneEvaluate(benchmark::State& state) {
  Scene s = make_scene(static_cast<int>(state.range(0)));
  std::vector<Eigen::Matrix4d> world;
  std::int64_t frame = 1;
  std::size_t changed = 0;
  for (auto _ : state) {
    (void)s.apply({frame++, Tick{}});
    s.world_from_nodes(world);
    changed += s.take_changes().updated.size();
    benchmark::DoNotOptimize(world.data());
  }
  state.counters["nodes_changed_per_frame"] = static_cast<double>(changed) / state.iterations();
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SceneEvaluate)->Arg(1000)->Unit(benchmark::kMicrosecond);

// Baseline: the same tracks sampled by a linear key scan into a map of local transforms, then
// every node's world transform by walking its parent chain to the root.
void BM_NaiveEvaluate(benchmark::State& state) {
  const Scene s = make_scene(static_cast<int>(state.range(0)));
  std::map<NodeId, Transform> local;
  for (const auto& [id, n] : s.nodes()) local[id] = n.local;
  std::map<NodeId, Eigen::Matrix4d> world;
  std::int64_t frame = 1;
  const double period = s.options().frame_period;
  for (auto _ : state) {
    for (const auto& [name, e] : s.animations()) {
      const double t = animation_time(e.clock.clock_time(frame, period), e.animation.duration(),
                                      e.animation.mode);
      for (const Track& track : e.animation.tracks) {
        const Eigen::Vector4d v = sample_linear_scan(track, t);
        Transform& tr = local[track.node];
        if (track.path == TrackPath::translation)
          tr.translation = v.head<3>();
        else if (track.path == TrackPath::rotation)
          tr.rotation = Eigen::Quaterniond(v[3], v[0], v[1], v[2]).normalized();
        else
          tr.scale = v.head<3>();
      }
    }
    for (const auto& [id, n] : s.nodes()) {
      Eigen::Matrix4d m = local[id].matrix();
      for (const Node* p = &n; !p->parent.empty();) {
        p = s.find(p->parent);
        m = local[p->id].matrix() * m;
      }
      world[id] = m;
    }
    ++frame;
    benchmark::DoNotOptimize(world.size());
  }
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_NaiveEvaluate)->Arg(1000)->Unit(benchmark::kMicrosecond);

// The persistence and hash costs the server pays when it saves or reports its state.
void BM_SceneStateHash(benchmark::State& state) {
  const Scene s = make_scene(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(s.state_hash());
}
BENCHMARK(BM_SceneStateHash)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
