#include "scene_mirror.h"

#include "core/log.h"

namespace studio::projector {

SceneMirror::Rebuilt SceneMirror::rebuild(const std::map<scene::NodeId, scene::Node>& nodes,
                                          scene::Scene& scene, scene_assets::AssetCache& cache,
                                          std::set<std::string>& failed_assets,
                                          scene_render::Renderer& renderer) {
  Rebuilt out;
  scene::Scene fresh(scene.options());
  std::set<scene::NodeId> placed;
  std::vector<const scene::Node*> pending;
  for (const auto& [id, n] : nodes) pending.push_back(&n);
  // Parents first: add what can be placed, repeat while that makes progress.
  for (bool progress = true; progress && !pending.empty();) {
    progress = false;
    std::vector<const scene::Node*> next;
    for (const scene::Node* n : pending) {
      if (!n->parent.empty() && !placed.contains(n->parent)) {
        next.push_back(n);
        continue;
      }
      if (fresh.apply(scene::Command{fresh.frame(), scene::AddNode{*n}})) {
        placed.insert(n->id);
        progress = true;
      } else {
        ++out.left_out;
      }
    }
    pending = std::move(next);
  }
  out.left_out += pending.size();
  out.placed = placed.size();
  for (const auto& [id, n] : fresh.nodes()) {
    if (n.kind != scene::NodeKind::model || n.asset.path.empty()) continue;
    if (failed_assets.contains(n.asset.path)) continue;
    auto asset = cache.load(n.asset.path);
    if (!asset) {
      STUDIO_LOG(warn, "projector") << "scene node " << id << ": " << asset.error().message;
      failed_assets.insert(n.asset.path);
      ++out.assets_failed;
      continue;
    }
    if (auto ok = renderer.upload(**asset); !ok) {
      STUDIO_LOG(warn, "projector") << ok.error().message;
      failed_assets.insert(n.asset.path);
      ++out.assets_failed;
    }
  }
  scene = std::move(fresh);
  return out;
}

}  // namespace studio::projector
