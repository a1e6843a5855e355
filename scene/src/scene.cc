#include "scene/scene.h"

#include <cmath>
#include <functional>
#include <utility>

#include "scene/serialize.h"

namespace studio::scene {
namespace {

constexpr std::int64_t kMaxFrame = std::int64_t{1} << 53;  // exact in a double

template <class... F>
struct Overload : F... {
  using F::operator()...;
};

}  // namespace

const char* command_name(const CommandOp& op) {
  static constexpr const char* kNames[] = {
      "add_node", "remove_node", "set_transform", "set_parent", "set_material",
      "set_visible", "add_animation", "remove_animation", "play", "pause", "seek", "set_speed",
      "tick", "batch"};
  return kNames[op.index()];
}

Expected<void> SceneOptions::validate() const {
  if (!std::isfinite(frame_period) || frame_period <= 0 || frame_period > 10)
    return fail("frame_period must be in (0, 10] seconds");
  return {};
}

Scene::Scene(SceneOptions options) : options_(options) {}

Scene::Scene(const Scene& o)
    : options_(o.options_), frame_(o.frame_), nodes_(o.nodes_), animations_(o.animations_),
      updated_(o.updated_), removed_(o.removed_) {
  rebuild_order();
}

Scene& Scene::operator=(const Scene& o) {
  if (this != &o) {
    Scene copy(o);
    *this = std::move(copy);
  }
  return *this;
}

// std::map nodes keep their addresses when the map is moved, so order_ stays valid.
Scene::Scene(Scene&& o) noexcept = default;
Scene& Scene::operator=(Scene&& o) noexcept = default;

const Node* Scene::find(const NodeId& id) const {
  auto it = nodes_.find(id);
  return it == nodes_.end() ? nullptr : &it->second;
}

bool Scene::in_subtree(const NodeId& id, const NodeId& root) const {
  // Walk up from id; parenting has no cycle, so this ends at the root.
  const Node* n = find(id);
  while (n) {
    if (n->id == root) return true;
    if (n->parent.empty()) return false;
    n = find(n->parent);
  }
  return false;
}

Expected<void> Scene::validate(const Command& c) const {
  if (c.frame < 0 || c.frame > kMaxFrame)
    return fail(std::string(command_name(c.op)) + ": frame " + std::to_string(c.frame) +
                " out of range");
  const std::string name = command_name(c.op);
  auto err = [&](const std::string& m) { return fail(name + ": " + m); };
  auto need_node = [&](const NodeId& id) -> Expected<const Node*> {
    const Node* n = find(id);
    if (!n) return err("unknown node '" + id + "'");
    return n;
  };
  auto need_animation = [&](const std::string& a) -> Expected<void> {
    if (!a.empty() && !animations_.contains(a)) return err("unknown animation '" + a + "'");
    return {};
  };
  return std::visit(
      Overload{
          [&](const AddNode& x) -> Expected<void> {
            if (auto ok = x.node.validate(); !ok) return err(ok.error().message);
            if (nodes_.contains(x.node.id)) return err("node '" + x.node.id + "' exists");
            if (!x.node.parent.empty() && !nodes_.contains(x.node.parent))
              return err("unknown parent '" + x.node.parent + "' of '" + x.node.id + "'");
            return {};
          },
          [&](const RemoveNode& x) -> Expected<void> {
            if (auto n = need_node(x.id); !n) return std::unexpected(n.error());
            for (const auto& [a, entry] : animations_)
              for (const Track& t : entry.animation.tracks)
                if (in_subtree(t.node, x.id))
                  return err("animation '" + a + "' drives '" + t.node + "' in the subtree of '" +
                             x.id + "'");
            return {};
          },
          [&](const SetTransform& x) -> Expected<void> {
            if (auto n = need_node(x.id); !n) return std::unexpected(n.error());
            if (auto ok = x.local.validate(); !ok) return err("'" + x.id + "': " + ok.error().message);
            return {};
          },
          [&](const SetParent& x) -> Expected<void> {
            if (auto n = need_node(x.id); !n) return std::unexpected(n.error());
            if (x.parent.empty()) return {};
            if (!nodes_.contains(x.parent)) return err("unknown parent '" + x.parent + "'");
            if (in_subtree(x.parent, x.id))
              return err("'" + x.id + "' -> '" + x.parent + "' would make a cycle");
            return {};
          },
          [&](const SetMaterial& x) -> Expected<void> {
            auto n = need_node(x.id);
            if (!n) return std::unexpected(n.error());
            if ((*n)->kind != NodeKind::model && (*n)->kind != NodeKind::actor)
              return err("'" + x.id + "' is a " + to_string((*n)->kind) + " node: no material");
            Node probe = **n;
            probe.material = x.material;
            if (auto ok = probe.validate(); !ok) return err(ok.error().message);
            return {};
          },
          [&](const SetVisible& x) -> Expected<void> {
            if (auto n = need_node(x.id); !n) return std::unexpected(n.error());
            return {};
          },
          [&](const AddAnimation& x) -> Expected<void> {
            if (auto ok = x.animation.validate(); !ok) return err(ok.error().message);
            if (animations_.contains(x.animation.name))
              return err("animation '" + x.animation.name + "' exists");
            for (const Track& t : x.animation.tracks)
              if (!nodes_.contains(t.node))
                return err("animation '" + x.animation.name + "' drives unknown node '" + t.node + "'");
            return {};
          },
          [&](const RemoveAnimation& x) -> Expected<void> {
            if (!animations_.contains(x.name)) return err("unknown animation '" + x.name + "'");
            return {};
          },
          [&](const Play& x) -> Expected<void> {
            if (x.from_time && !std::isfinite(*x.from_time)) return err("from_time is not finite");
            if (x.mode && static_cast<unsigned>(*x.mode) > 2) return err("bad play mode");
            return need_animation(x.animation);
          },
          [&](const Pause& x) -> Expected<void> { return need_animation(x.animation); },
          [&](const Seek& x) -> Expected<void> {
            if (!std::isfinite(x.time)) return err("time is not finite");
            return need_animation(x.animation);
          },
          [&](const SetSpeed& x) -> Expected<void> {
            if (!std::isfinite(x.speed) || std::abs(x.speed) > 1000)
              return err("speed must be finite with |speed| <= 1000");
            return need_animation(x.animation);
          },
          [&](const Tick&) -> Expected<void> { return {}; },
          [&](const Batch&) -> Expected<void> { return {}; },  // checked command by command
      },
      c.op);
}

void Scene::touch(Node& node, std::int64_t frame) {
  node.frame = frame;
  updated_.insert(node.id);
}

void Scene::mutate(const Command& c) {
  const std::int64_t f = c.frame;
  auto for_clocks = [&](const std::string& a, auto&& fn) {
    for (auto& [name, entry] : animations_)
      if (a.empty() || a == name) fn(entry);
  };
  std::visit(
      Overload{
          [&](const AddNode& x) {
            Node n = x.node;
            n.local = n.local.normalized();
            n.frame = f;
            removed_.erase(n.id);
            updated_.insert(n.id);
            nodes_.emplace(n.id, std::move(n));
            rebuild_order();
          },
          [&](const RemoveNode& x) {
            std::vector<NodeId> doomed;
            for (const auto& [id, n] : nodes_)
              if (in_subtree(id, x.id)) doomed.push_back(id);
            for (const NodeId& id : doomed) {
              nodes_.erase(id);
              updated_.erase(id);
              removed_.insert(id);
            }
            rebuild_order();
          },
          [&](const SetTransform& x) {
            Node& n = nodes_.at(x.id);
            n.local = x.local.normalized();
            touch(n, f);
          },
          [&](const SetParent& x) {
            Node& n = nodes_.at(x.id);
            n.parent = x.parent;
            touch(n, f);
            rebuild_order();
          },
          [&](const SetMaterial& x) {
            Node& n = nodes_.at(x.id);
            n.material = x.material;
            touch(n, f);
          },
          [&](const SetVisible& x) {
            Node& n = nodes_.at(x.id);
            n.visible = x.visible;
            touch(n, f);
          },
          [&](const AddAnimation& x) {
            AnimationEntry e{x.animation, AnimationClock{}};
            for (Track& t : e.animation.tracks)
              if (t.path == TrackPath::rotation)
                for (auto& v : t.values) v.normalize();
            e.clock.anchor_frame = f;
            animations_.emplace(x.animation.name, std::move(e));
          },
          [&](const RemoveAnimation& x) { animations_.erase(x.name); },
          [&](const Play& x) {
            for_clocks(x.animation, [&](AnimationEntry& e) {
              e.clock.anchor_time = x.from_time ? *x.from_time
                                                : e.clock.clock_time(f, options_.frame_period);
              e.clock.anchor_frame = f;
              e.clock.playing = true;
              if (x.mode) e.animation.mode = *x.mode;
            });
          },
          [&](const Pause& x) {
            for_clocks(x.animation, [&](AnimationEntry& e) {
              e.clock.anchor_time = e.clock.clock_time(f, options_.frame_period);
              e.clock.anchor_frame = f;
              e.clock.playing = false;
            });
          },
          [&](const Seek& x) {
            for_clocks(x.animation, [&](AnimationEntry& e) {
              e.clock.anchor_time = x.time;
              e.clock.anchor_frame = f;
            });
          },
          [&](const SetSpeed& x) {
            for_clocks(x.animation, [&](AnimationEntry& e) {
              e.clock.anchor_time = e.clock.clock_time(f, options_.frame_period);
              e.clock.anchor_frame = f;
              e.clock.speed = x.speed;
            });
          },
          [&](const Tick&) { evaluate(f); },
          [&](const Batch&) {},
      },
      c.op);
}

Expected<void> Scene::apply(const Command& c) {
  if (const auto* batch = std::get_if<Batch>(&c.op)) {
    if (c.frame < 0 || c.frame > kMaxFrame) return fail("batch: frame out of range");
    Scene scratch(*this);
    for (std::size_t i = 0; i < batch->commands.size(); ++i) {
      const Command& inner = batch->commands[i];
      if (std::holds_alternative<Batch>(inner.op))
        return fail("batch: command " + std::to_string(i) + ": nested batch");
      if (auto ok = scratch.apply(inner); !ok)
        return fail("batch: command " + std::to_string(i) + ": " + ok.error().message);
    }
    *this = std::move(scratch);
    return {};
  }
  if (auto ok = validate(c); !ok) return ok;
  mutate(c);
  return {};
}

void Scene::evaluate(std::int64_t f) {
  frame_ = f;
  for (auto& [name, entry] : animations_) {
    const double t = animation_time(entry.clock.clock_time(f, options_.frame_period),
                                    entry.animation.duration(), entry.animation.mode);
    for (const Track& track : entry.animation.tracks) {
      Node& n = nodes_.at(track.node);
      const Eigen::Vector4d v = sample(track, t);
      bool changed = false;
      switch (track.path) {
        case TrackPath::translation:
          changed = n.local.translation != v.head<3>();
          n.local.translation = v.head<3>();
          break;
        case TrackPath::rotation: {
          const Eigen::Quaterniond q = Eigen::Quaterniond(v[3], v[0], v[1], v[2]).normalized();
          changed = n.local.rotation.coeffs() != q.coeffs();
          n.local.rotation = q;
          break;
        }
        case TrackPath::scale:
          changed = n.local.scale != v.head<3>();
          n.local.scale = v.head<3>();
          break;
      }
      if (changed) touch(n, f);
    }
  }
}

void Scene::rebuild_order() {
  order_.clear();
  parent_index_.clear();
  std::map<NodeId, std::vector<const Node*>> children;
  for (const auto& [id, n] : nodes_) children[n.parent].push_back(&n);
  // Depth-first from the root ("" key), iteratively (no recursion depth limit).
  std::vector<std::pair<const Node*, int>> stack;
  auto push_children = [&](const NodeId& parent, int parent_index) {
    auto it = children.find(parent);
    if (it == children.end()) return;
    for (auto c = it->second.rbegin(); c != it->second.rend(); ++c)
      stack.emplace_back(*c, parent_index);
  };
  push_children("", -1);
  while (!stack.empty()) {
    auto [n, p] = stack.back();
    stack.pop_back();
    order_.push_back(n);
    parent_index_.push_back(p);
    push_children(n->id, static_cast<int>(order_.size()) - 1);
  }
}

Expected<Eigen::Matrix4d> Scene::world_from_node(const NodeId& id) const {
  const Node* n = find(id);
  if (!n) return fail("unknown node '" + id + "'");
  Eigen::Matrix4d m = n->local.matrix();
  while (!n->parent.empty()) {
    n = find(n->parent);
    m = n->local.matrix() * m;
  }
  return m;
}

bool Scene::effectively_visible(const NodeId& id) const {
  for (const Node* n = find(id); n; n = n->parent.empty() ? nullptr : find(n->parent))
    if (!n->visible) return false;
  return find(id) != nullptr;
}

void Scene::world_from_nodes(std::vector<Eigen::Matrix4d>& out) const {
  out.resize(order_.size());
  for (std::size_t i = 0; i < order_.size(); ++i) {
    const int p = parent_index_[i];
    out[i] = p < 0 ? order_[i]->local.matrix() : Eigen::Matrix4d(out[p] * order_[i]->local.matrix());
  }
}

ChangeSet Scene::take_changes() {
  ChangeSet c;
  c.updated.assign(updated_.begin(), updated_.end());
  c.removed.assign(removed_.begin(), removed_.end());
  updated_.clear();
  removed_.clear();
  return c;
}

std::uint64_t Scene::state_hash() const {
  const std::vector<std::uint8_t> bytes = serialize(*this);
  return fnv1a64(bytes.data(), bytes.size());
}

Expected<void> Scene::check_invariants() const {
  if (auto ok = options_.validate(); !ok) return ok;
  for (const auto& [id, n] : nodes_) {
    if (id != n.id) return fail("node stored under '" + id + "' has id '" + n.id + "'");
    if (auto ok = n.validate(); !ok) return ok;
    if (!n.parent.empty() && !nodes_.contains(n.parent))
      return fail("node '" + id + "' has unknown parent '" + n.parent + "'");
    if (std::abs(n.local.rotation.norm() - 1) > 1e-9)
      return fail("node '" + id + "' has a rotation that is not unit");
  }
  // Every node is reachable from the root exactly once iff parenting has no cycle.
  if (order_.size() != nodes_.size()) return fail("parenting has a cycle");
  for (const auto& [name, e] : animations_) {
    if (name != e.animation.name) return fail("animation stored under '" + name + "' is misnamed");
    if (auto ok = e.animation.validate(); !ok) return ok;
    for (const Track& t : e.animation.tracks)
      if (!nodes_.contains(t.node))
        return fail("animation '" + name + "' drives unknown node '" + t.node + "'");
    if (!std::isfinite(e.clock.speed) || !std::isfinite(e.clock.anchor_time))
      return fail("animation '" + name + "' has a clock that is not finite");
  }
  return {};
}

ReplayResult replay(Scene& scene, const std::vector<Command>& log) {
  ReplayResult r;
  for (const Command& c : log) {
    if (scene.apply(c))
      ++r.applied;
    else
      ++r.rejected;
  }
  return r;
}

}  // namespace studio::scene
