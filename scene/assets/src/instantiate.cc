#include "scene_assets/instantiate.h"

#include <map>

namespace studio::scene_assets {

Instance instantiate(const Asset& asset, const std::string& root_id, const std::string& parent,
                     std::int64_t frame) {
  Instance out;
  std::map<std::string, int> uses;
  std::map<std::string, scene::NodeId> id_of_name;  // first node of each name
  for (std::size_t i = 0; i < asset.nodes.size(); ++i) {
    const AssetNode& an = asset.nodes[i];
    scene::Node n;
    if (i == 0) {
      n.id = root_id;
      n.parent = parent;
    } else {
      const std::string base = root_id + "/" + (an.name.empty() ? "node" : an.name);
      const int k = ++uses[base];
      n.id = k == 1 ? base : base + "#" + std::to_string(k);
      n.parent = out.node_ids[static_cast<std::size_t>(an.parent)];
    }
    id_of_name.emplace(an.name, n.id);
    n.local = an.local;
    if (!an.meshes.empty()) {
      n.kind = scene::NodeKind::model;
      n.asset = {asset.path, asset.sha256, an.meshes};
    } else if (an.light >= 0) {
      n.kind = scene::NodeKind::light;
      n.light = asset.lights[static_cast<std::size_t>(an.light)];
    }
    out.node_ids.push_back(n.id);
    out.commands.push_back({frame, scene::AddNode{std::move(n)}});
  }
  for (const scene::Animation& a : asset.animations) {
    scene::Animation anim = a;
    anim.name = root_id + "/" + a.name;
    std::vector<scene::Track> kept;
    for (scene::Track t : anim.tracks) {
      auto it = id_of_name.find(t.node);
      if (it == id_of_name.end()) continue;  // a channel for a node the hierarchy lacks
      t.node = it->second;
      kept.push_back(std::move(t));
    }
    anim.tracks = std::move(kept);
    if (!anim.tracks.empty()) out.commands.push_back({frame, scene::AddAnimation{std::move(anim)}});
  }
  return out;
}

Eigen::AlignedBox3d world_bounds(const scene::Scene& scene, const scene::NodeId& id,
                                 const Asset& asset) {
  Eigen::AlignedBox3d box;
  const scene::Node* n = scene.find(id);
  if (!n || n->kind != scene::NodeKind::model || n->asset.path != asset.path) return box;
  const Eigen::Matrix4d world_from_node = *scene.world_from_node(id);
  auto add_mesh = [&](std::size_t m) {
    if (m >= asset.meshes.size() || asset.meshes[m].bounds.isEmpty()) return;
    const Eigen::AlignedBox3f& b = asset.meshes[m].bounds;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3f corner = b.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
      box.extend((world_from_node * corner.cast<double>().homogeneous()).head<3>());
    }
  };
  if (n->asset.meshes.empty())
    for (std::size_t m = 0; m < asset.meshes.size(); ++m) add_mesh(m);
  else
    for (std::uint32_t m : n->asset.meshes) add_mesh(m);
  return box;
}

Expected<std::shared_ptr<const Asset>> AssetCache::load(const std::string& path) {
  if (auto it = assets_.find(path); it != assets_.end()) return it->second;
  auto a = load_asset(path);
  if (!a) return std::unexpected(a.error());
  auto shared = std::make_shared<const Asset>(std::move(*a));
  assets_.emplace(path, shared);
  return shared;
}

std::shared_ptr<const Asset> AssetCache::find(const std::string& path) const {
  auto it = assets_.find(path);
  return it == assets_.end() ? nullptr : it->second;
}

}  // namespace studio::scene_assets
