#pragma once
// The projector benches' input: 8 meshes of the simulated actor's arm swing, 40 ms apart, in
// alternating tessellations so consecutive meshes never share vertices (as the hull's do not).
// Header-only: the benches that include it link studio_sim.

#include <cstdint>
#include <random>
#include <vector>

#include "projector/actor_mesh.h"
#include "sim/actor.h"

namespace studio::projector::testing {

inline constexpr int64_t kSwingFrameNs = 40'000'000;

inline const std::vector<ActorMesh>& swing_meshes() {
  static const std::vector<ActorMesh> m = [] {
    sim::Actor::Options ao;
    ao.motion = sim::Motion::arm_swing;
    const sim::Actor actor(ao);
    std::vector<ActorMesh> out;
    for (int f = 0; f < 8; ++f) {
      const sim::TriangleMesh body = actor.body_at(2.0 + f * 0.04).mesh(f % 2 ? 22 : 24);
      ActorMesh a;
      a.vertices = body.vertices;
      a.triangles = body.triangles;
      a.capture_ns = 1'000'000'000 + f * kSwingFrameNs;
      out.push_back(std::move(a));
    }
    return out;
  }();
  return m;
}

// `frames` meshes of the arm swing from t = 2 s, 40 ms apart, alternating tessellations, every
// vertex moved by isotropic Gaussian noise of `noise_m` per axis (a hull's surface error).
inline std::vector<ActorMesh> noisy_swing_meshes(int frames, double noise_m, unsigned seed) {
  sim::Actor::Options ao;
  ao.motion = sim::Motion::arm_swing;
  const sim::Actor actor(ao);
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, float(noise_m));
  std::vector<ActorMesh> out;
  for (int f = 0; f < frames; ++f) {
    const sim::TriangleMesh body = actor.body_at(2.0 + f * 0.04).mesh(f % 2 ? 22 : 24);
    ActorMesh a;
    a.vertices = body.vertices;
    for (auto& v : a.vertices) v += Eigen::Vector3f(g(rng), g(rng), g(rng));
    a.triangles = body.triangles;
    a.capture_ns = 1'000'000'000 + f * kSwingFrameNs;
    out.push_back(std::move(a));
  }
  return out;
}

}  // namespace studio::projector::testing
