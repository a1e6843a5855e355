#include "scene_mirror.h"

#include "core/log.h"

namespace studio::projector {

void SceneMirror::update(scene::Node node, double now) {
  auto it = nodes_.find(node.id);
  if (it != nodes_.end()) {
    scene::Node before = it->second;
    before.frame = node.frame;  // a new stamp alone is no change
    if (before == node) {
      it->second = std::move(node);
      return;
    }
    changed_[node.id] = now;
  }
  nodes_[node.id] = std::move(node);
  dirty_ = true;
}

bool SceneMirror::dirty(double now) {
  for (auto it = changed_.begin(); it != changed_.end();) {
    if (now - it->second >= settle_s_) {  // settled: joins the still layer
      it = changed_.erase(it);
      dirty_ = true;
    } else {
      ++it;
    }
  }
  return dirty_;
}

std::set<scene::NodeId> SceneMirror::moving(double now) const {
  std::set<scene::NodeId> out;
  for (const auto& [id, t] : changed_)
    if (now - t < settle_s_) out.insert(id);
  return out;
}

SceneMirror::Rebuilt RenderScene::rebuild(const std::map<scene::NodeId, scene::Node>& nodes,
                                          const std::set<scene::NodeId>& moving,
                                          scene_render::Renderer& renderer) {
  auto r = SceneMirror::rebuild(nodes, scene, cache, failed_assets, renderer);
  layers = split_scene(scene, moving);
  return r;
}

Expected<projector_render::FrameInfo> RenderScene::draw(projector_render::FrameRenderer& fr,
                                                        const Eigen::Vector3d& eye,
                                                        std::span<const ActorMesh> masks,
                                                        bool cache) const {
  if (cache) return fr.render({layers.still, layers.still_version, &layers.moving}, eye, masks);
  auto n = fr.render(scene, eye, masks);
  if (!n) return std::unexpected(n.error());
  return projector_render::FrameInfo{.masks = *n};
}

Expected<projector_render::FrameInfo> RenderScene::prepare(projector_render::FrameRenderer& fr,
                                                           const Eigen::Vector3d& eye,
                                                           bool cache) const {
  if (cache) return fr.prepare({layers.still, layers.still_version, &layers.moving}, eye);
  return fr.prepare(scene, eye);
}

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
