#pragma once
// What a scene file (scene.yaml) describes, as plain data (read by scene_config/scene_yaml.h),
// and how it becomes a Scene: the set (a glTF/GLB/OBJ file) instantiated under `set_id`, extra
// nodes, extra animations, nodes drawn high-contrast, animations to start at given frames, and an
// optional default view.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"
#include "scene_assets/instantiate.h"

namespace studio::scene_assets {

struct NodeSpec {
  std::string id;
  std::string parent;
  std::string asset;    // a model's file (path resolved by the reader)
  std::string actor;    // an actor node's actor id
  std::vector<double> translation{0, 0, 0};
  std::vector<double> rotation{0, 0, 0, 1};  // quaternion x, y, z, w
  std::vector<double> scale{1, 1, 1};
  std::vector<double> colour{1, 1, 1, 1};
  std::string texture;
  bool high_contrast = false;
  bool visible = true;
};

struct TrackSpec {
  std::string node;
  scene::TrackPath path = scene::TrackPath::translation;
  scene::Interpolation interpolation = scene::Interpolation::linear;
  std::vector<double> times;
  std::vector<double> values;  // 3 per key (translation, scale) or 4 (rotation x, y, z, w)
};

struct AnimationSpec {
  std::string name;
  scene::PlayMode mode = scene::PlayMode::loop;
  std::vector<TrackSpec> tracks;
};

struct PlaySpec {
  std::string animation;  // "" = all
  std::int64_t at_frame = 0;
  std::optional<scene::PlayMode> mode;
  double speed = 1.0;
};

struct ViewSpec {
  std::vector<double> eye{0, 1.7, 5};
  std::vector<double> at{0, 1, 0};
  double fov_deg = 60;
};

struct SceneDescription {
  std::string file;  // the scene file itself, for messages
  std::string set;   // resolved path; may be empty (a scene of extra nodes only)
  std::string set_id = "set";
  double fps = 25;
  std::vector<NodeSpec> nodes;
  std::vector<AnimationSpec> animations;
  std::vector<std::string> high_contrast;
  std::vector<PlaySpec> play;
  std::optional<ViewSpec> view;
};

// Builds the scene at studio frame `frame` (set, nodes, animations, high-contrast flags, play
// commands, then one Tick). Loads every asset through `cache`. Errors are one line naming the
// scene file and what failed ("scene.yaml: nodes: unknown parent 'x' of 'y'").
Expected<scene::Scene> build_scene(const SceneDescription& d, AssetCache& cache,
                                   std::int64_t frame = 0);

}  // namespace studio::scene_assets
