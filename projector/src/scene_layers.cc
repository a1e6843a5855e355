#include "projector/scene_layers.h"

#include <vector>

namespace studio::projector {

SceneLayers split_scene(const scene::Scene& all, const std::set<scene::NodeId>& moving) {
  const auto& order = all.order();
  const auto& parent = all.parent_index();
  const std::size_t n = order.size();
  std::vector<char> moves(n, 0), needed(n, 0);
  bool moving_light = false;
  for (std::size_t i = 0; i < n; ++i) {  // parents before children
    moves[i] = moving.contains(order[i]->id) || (parent[i] >= 0 && moves[std::size_t(parent[i])]);
    moving_light = moving_light || (moves[i] && order[i]->kind == scene::NodeKind::light);
  }
  SceneLayers out{scene::Scene(all.options()), scene::Scene(all.options()), 0, 0, moving_light};
  if (moving_light) {
    out.still = all;
    out.still_version = out.still.nodes_hash();
    return out;
  }
  for (std::size_t i = n; i-- > 0;) {  // children before parents: ancestors of what is needed
    needed[i] = needed[i] || moves[i] || order[i]->kind == scene::NodeKind::light;
    if (needed[i] && parent[i] >= 0) needed[std::size_t(parent[i])] = 1;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const scene::Node& node = *order[i];
    if (!moves[i]) (void)out.still.apply({0, scene::AddNode{node}});
    if (!needed[i]) continue;
    if (moves[i] || node.kind == scene::NodeKind::light) {
      (void)out.moving.apply({0, scene::AddNode{node}});
      out.moving_nodes += moves[i] ? 1 : 0;
    } else {
      scene::Node group;
      group.id = node.id;
      group.parent = node.parent;
      group.kind = scene::NodeKind::group;
      group.local = node.local;
      group.visible = node.visible;
      (void)out.moving.apply({0, scene::AddNode{group}});
    }
  }
  out.still_version = out.still.nodes_hash();
  return out;
}

}  // namespace studio::projector
