#pragma once
// The master scene graph (TCSVT 2004 §V: the virtual scene server): nodes, animations with their
// clocks, and the studio frame of the last evaluation. Pure: no DDS, GL or YAML; the scene server
// node is a thin layer that turns SceneCommand samples into Commands, sends itself a Tick per
// studio frame, publishes take_changes() as SceneNode instances (disposing the removed ones),
// persists serialize() atomically, and reports state_hash().
//
// Invariants (check_invariants() verifies them; every public mutation keeps them):
//   - node ids are unique and valid, every parent exists, parenting has no cycle;
//   - every animation is valid, has a unique name and drives only existing nodes;
//   - every stored rotation is a unit quaternion.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/animation.h"
#include "scene/command.h"
#include "scene/node.h"

namespace studio::scene {

struct SceneOptions {
  double frame_period = 0.04;  // seconds per studio frame (25 fps, the paper's)
  Expected<void> validate() const;
  bool operator==(const SceneOptions&) const = default;
};

struct AnimationEntry {
  Animation animation;
  AnimationClock clock;
  bool operator==(const AnimationEntry&) const = default;
};

// Nodes added or changed / removed since the last take_changes(), sorted by id. A node removed
// and re-added shows as updated only.
struct ChangeSet {
  std::vector<NodeId> updated;
  std::vector<NodeId> removed;
  bool empty() const { return updated.empty() && removed.empty(); }
};

class Scene {
 public:
  explicit Scene(SceneOptions options = {});
  Scene(const Scene& other);
  Scene& operator=(const Scene& other);
  Scene(Scene&& other) noexcept;
  Scene& operator=(Scene&& other) noexcept;

  // Validates, then applies completely; on error the scene is unchanged. Errors are one line
  // naming the command and the offending id: "set_parent: 'a' -> 'b' would make a cycle".
  Expected<void> apply(const Command& command);

  const SceneOptions& options() const { return options_; }
  const std::map<NodeId, Node>& nodes() const { return nodes_; }
  const Node* find(const NodeId& id) const;
  const std::map<std::string, AnimationEntry>& animations() const { return animations_; }
  std::int64_t frame() const { return frame_; }  // frame of the last Tick

  // world_from_node = parent chain of parent_from_node matrices. Error for an unknown id.
  Expected<Eigen::Matrix4d> world_from_node(const NodeId& id) const;
  // True when the node and all its ancestors are visible.
  bool effectively_visible(const NodeId& id) const;

  // Nodes with parents before children (depth first, children by id) and, aligned with it, the
  // index of each node's parent in this order (-1 at the root). Stable until the next change of
  // structure (add, remove, re-parent).
  const std::vector<const Node*>& order() const { return order_; }
  const std::vector<int>& parent_index() const { return parent_index_; }
  // world_from_node of every node in order(), in one pass (out is resized; no allocation when it
  // already has the size).
  void world_from_nodes(std::vector<Eigen::Matrix4d>& out) const;

  // Nodes changed since the last call (what the server publishes next).
  ChangeSet take_changes();
  bool has_changes() const { return !updated_.empty() || !removed_.empty(); }

  // A 64-bit hash of the whole state: options, frame, every node, every animation and its clock
  // (the bytes of serialize()). Equal states give equal hashes on every host.
  std::uint64_t state_hash() const;

  Expected<void> check_invariants() const;

 private:
  friend Expected<Scene> deserialize(const std::vector<std::uint8_t>& bytes);

  Expected<void> validate(const Command& c) const;
  void mutate(const Command& c);
  void evaluate(std::int64_t frame);
  void rebuild_order();
  void touch(Node& node, std::int64_t frame);
  bool in_subtree(const NodeId& id, const NodeId& root) const;

  SceneOptions options_;
  std::int64_t frame_ = 0;
  std::map<NodeId, Node> nodes_;
  std::map<std::string, AnimationEntry> animations_;
  std::vector<const Node*> order_;
  std::vector<int> parent_index_;
  std::set<NodeId> updated_, removed_;
};

// Replays a command log on a scene: every command applied in order, errors counted.
struct ReplayResult {
  std::size_t applied = 0;
  std::size_t rejected = 0;
};
ReplayResult replay(Scene& scene, const std::vector<Command>& log);

}  // namespace studio::scene
