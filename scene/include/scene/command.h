#pragma once
// Commands that change a Scene (what the SceneCommand topic carries, and what the server logs).
//
// Every command names the studio frame at which it takes effect (`frame`, >= 0, DESIGN §5):
// a node change stamps the node with it, a clock change re-anchors the animation clock there
// (so "start animation A at frame N" is Play{A} at frame N: before N the animation rests at its
// start time). Tick evaluates every animation at `frame` (the server sends itself one per studio
// frame). An animation name "" in Play / Pause / Seek / SetSpeed means every animation.
//
// Scene::apply validates a command completely before changing anything: it either applies the
// whole change or returns an error and leaves the scene exactly as it was. A Batch applies its
// commands in order, all or none (loading a set is one Batch: remove the old set and its
// animations, add the new nodes and animations).

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "scene/animation.h"
#include "scene/node.h"

namespace studio::scene {

struct AddNode {
  Node node;
  bool operator==(const AddNode&) const = default;
};
// Removes the node and its whole subtree. Refused while an animation drives a node of it.
struct RemoveNode {
  NodeId id;
  bool operator==(const RemoveNode&) const = default;
};
// Live control: move a node (its local transform, parent_from_node). A node driven by an
// animation follows the animation again at the next Tick on the driven paths.
struct SetTransform {
  NodeId id;
  Transform local;
  bool operator==(const SetTransform&) const = default;
};
// Re-parents a node keeping its local transform; "" = the root. Refused if it makes a cycle.
struct SetParent {
  NodeId id;
  NodeId parent;
  bool operator==(const SetParent&) const = default;
};
// Model and actor nodes only.
struct SetMaterial {
  NodeId id;
  Material material;
  bool operator==(const SetMaterial&) const = default;
};
struct SetVisible {
  NodeId id;
  bool visible = true;
  bool operator==(const SetVisible&) const = default;
};
// Every track must drive an existing node; the name must be new.
struct AddAnimation {
  Animation animation;
  bool operator==(const AddAnimation&) const = default;
};
struct RemoveAnimation {
  std::string name;
  bool operator==(const RemoveAnimation&) const = default;
};
// Plays from `from_time` (clock time, seconds) or, when absent, from where the clock is at the
// command's frame; `mode`, when given, replaces the animation's play mode.
struct Play {
  std::string animation;
  std::optional<double> from_time = std::nullopt;
  std::optional<PlayMode> mode = std::nullopt;
  bool operator==(const Play&) const = default;
};
struct Pause {
  std::string animation;
  bool operator==(const Pause&) const = default;
};
// Sets the clock time (seconds); playing or paused stays as it was.
struct Seek {
  std::string animation;
  double time = 0.0;
  bool operator==(const Seek&) const = default;
};
// |speed| <= 1000 (negative plays backwards).
struct SetSpeed {
  std::string animation;
  double speed = 1.0;
  bool operator==(const SetSpeed&) const = default;
};
struct Tick {
  bool operator==(const Tick&) const = default;
};
struct Command;
// Commands applied in order, all or none; no nested batches.
struct Batch {
  std::vector<Command> commands;
  bool operator==(const Batch&) const;
};

using CommandOp = std::variant<AddNode, RemoveNode, SetTransform, SetParent, SetMaterial,
                               SetVisible, AddAnimation, RemoveAnimation, Play, Pause, Seek,
                               SetSpeed, Tick, Batch>;

struct Command {
  std::int64_t frame = 0;
  CommandOp op;
  bool operator==(const Command&) const = default;
};

inline bool Batch::operator==(const Batch& o) const { return commands == o.commands; }

// "add_node", "remove_node", ... (for logs and counters).
const char* command_name(const CommandOp& op);

}  // namespace studio::scene
