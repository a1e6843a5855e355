#pragma once
// Random scene commands for tests and benchmarks (and, later, the server's 10 000-command burst
// test): a deterministic mix of valid and invalid commands of every kind, drawn against the
// current scene so that most refer to existing nodes and animations.

#include <cstdint>
#include <random>

#include "scene/command.h"
#include "scene/scene.h"

namespace studio::scene::testing {

class RandomCommandSource {
 public:
  explicit RandomCommandSource(std::uint64_t seed) : rng_(seed) {}
  Command next(const Scene& scene);

 private:
  NodeId some_node(const Scene& scene, bool allow_unknown = true);
  std::string some_animation(const Scene& scene);
  Transform some_transform(bool allow_bad);
  Node some_node_to_add(const Scene& scene);
  Animation some_animation_to_add(const Scene& scene);
  Command make(const Scene& scene, int depth);

  std::mt19937_64 rng_;
  std::int64_t frame_ = 0;
  int serial_ = 0;
};

}  // namespace studio::scene::testing
