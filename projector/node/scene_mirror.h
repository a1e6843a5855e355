#pragma once
// The projector's copy of the virtual scene: the alive studio/scene/node instances (keyed by
// node_id; a disposed instance removes its node) rebuilt into a scene::Scene when they changed,
// and the assets the model nodes name loaded from their paths (scene_assets::AssetCache) and
// uploaded to the renderer. A node that cannot be placed (its parent never arrived, a failed
// validation) is left out and counted; an unreadable asset is reported once and its nodes are
// not drawn (Renderer::check_assets).

#include <map>
#include <set>
#include <string>

#include "scene/scene.h"
#include "scene_assets/instantiate.h"
#include "scene_render/renderer.h"

namespace studio::projector {

class SceneMirror {
 public:
  void update(scene::Node node) {
    nodes_[node.id] = std::move(node);
    dirty_ = true;
  }
  void remove(const scene::NodeId& id) { dirty_ = nodes_.erase(id) > 0 || dirty_; }
  bool dirty() const { return dirty_; }
  const std::map<scene::NodeId, scene::Node>& nodes() const { return nodes_; }

  struct Rebuilt {
    std::size_t placed = 0, left_out = 0, assets_failed = 0;
  };
  // Rebuilds `scene` from `nodes` (parents before children) and uploads missing assets.
  static Rebuilt rebuild(const std::map<scene::NodeId, scene::Node>& nodes, scene::Scene& scene,
                         scene_assets::AssetCache& cache, std::set<std::string>& failed_assets,
                         scene_render::Renderer& renderer);
  void clean() { dirty_ = false; }

 private:
  std::map<scene::NodeId, scene::Node> nodes_;
  bool dirty_ = false;
};

}  // namespace studio::projector
