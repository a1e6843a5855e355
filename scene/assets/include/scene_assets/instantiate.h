#pragma once
// An asset becomes scene nodes and animations: the "load set" step of the scene server.
//
// Every AssetNode becomes a scene node: the root gets `root_id` (child of `parent`), every other
// node "<root_id>/<name>" (a name used twice gets "#2", "#3", ... in file order). A node with
// meshes is a model (asset = path + hash + its mesh indices), a node with a light is a light,
// the rest are groups. Every animation of the asset becomes "<root_id>/<name>" driving those ids,
// on the same scene clock as any other animation.

#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/command.h"
#include "scene/scene.h"
#include "scene_assets/asset.h"

namespace studio::scene_assets {

struct Instance {
  std::vector<scene::Command> commands;  // AddNode (parents first), then AddAnimation
  std::vector<scene::NodeId> node_ids;   // aligned with Asset::nodes
};

Instance instantiate(const Asset& asset, const std::string& root_id, const std::string& parent,
                     std::int64_t frame);

// World-space bounding box of a model node's meshes (empty box for other nodes or an asset
// that does not match the node's path).
Eigen::AlignedBox3d world_bounds(const scene::Scene& scene, const scene::NodeId& id,
                                 const Asset& asset);

// Assets by path, loaded once each (shared with the renderer).
class AssetCache {
 public:
  Expected<std::shared_ptr<const Asset>> load(const std::string& path);
  std::shared_ptr<const Asset> find(const std::string& path) const;
  const std::map<std::string, std::shared_ptr<const Asset>>& all() const { return assets_; }

 private:
  std::map<std::string, std::shared_ptr<const Asset>> assets_;
};

}  // namespace studio::scene_assets
