#pragma once
// The projector's copy of the virtual scene: the alive studio/scene/node instances (keyed by
// node_id; a disposed instance removes its node) rebuilt into a scene::Scene when they changed,
// and the assets the model nodes name loaded from their paths (scene_assets::AssetCache) and
// uploaded to the renderer. A node that cannot be placed (its parent never arrived, a failed
// validation) is left out and counted; an unreadable asset is reported once and its nodes are
// not drawn (Renderer::check_assets).
//
// Scene cache (issue 15): the mirror notes when each node last changed (a sample that differs
// from the node's previous state, its frame stamp aside); a node changed within `settle_s` is
// moving (drawn every frame with its subtree, projector/scene_layers.h), the others are still
// (cached). A moving node that settles makes the mirror dirty, so the layers are split again and
// the still layer, now holding it, is drawn once more and cached.

#include <map>
#include <set>
#include <string>

#include "projector/scene_layers.h"
#include "projector_render/frame_renderer.h"
#include "scene/scene.h"
#include "scene_assets/instantiate.h"
#include "scene_render/renderer.h"

namespace studio::projector {

class SceneMirror {
 public:
  explicit SceneMirror(double settle_s = 1.0) : settle_s_(settle_s) {}
  // `now`: seconds on a monotonic clock.
  void update(scene::Node node, double now);
  void remove(const scene::NodeId& id) {
    changed_.erase(id);
    dirty_ = nodes_.erase(id) > 0 || dirty_;
  }
  // Dirty: a node changed, or a moving node settled by `now`.
  bool dirty(double now);
  // The nodes changed within settle_s of `now`.
  std::set<scene::NodeId> moving(double now) const;
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
  double settle_s_;
  std::map<scene::NodeId, scene::Node> nodes_;
  std::map<scene::NodeId, double> changed_;  // when a node last changed (moving ones)
  bool dirty_ = false;
};

// The render thread's copy of the scene: rebuilt from the mirror's nodes when they changed, with
// its assets, and split into the still and moving layers.
struct RenderScene {
  scene::Scene scene;
  scene_assets::AssetCache cache;
  std::set<std::string> failed_assets;
  SceneLayers layers;
  // Rebuilds the scene (SceneMirror::rebuild) and its layers (moving: SceneMirror::moving).
  SceneMirror::Rebuilt rebuild(const std::map<scene::NodeId, scene::Node>& nodes,
                               const std::set<scene::NodeId>& moving,
                               scene_render::Renderer& renderer);
  // The frame from the layers (the scene cache), or from the whole scene when `cache` is off.
  Expected<projector_render::FrameInfo> draw(projector_render::FrameRenderer& fr,
                                             const Eigen::Vector3d& eye,
                                             std::span<const ActorMesh> masks, bool cache) const;
  // The scene alone, ahead of its masks (FrameRenderer::prepare; late latching).
  Expected<projector_render::FrameInfo> prepare(projector_render::FrameRenderer& fr,
                                                const Eigen::Vector3d& eye, bool cache) const;
};

}  // namespace studio::projector
